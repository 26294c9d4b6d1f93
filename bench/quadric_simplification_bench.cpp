// Simplifying an over-fine base (issue 14): the 70k-face Stanford bunny split 1-to-4 once and
// twice (278k and 1.1M faces: the same surface, finer faces), simplified to edges of 0.005
// (about the refinement's edge length at --scale 0.1 with the apples swatch) within 2e-4 (a
// twentieth of that job's shell height), as `surface` does before quilting over such a base.
#include <benchmark/benchmark.h>

#include <string>

#include "core/mesh/mesh_io.h"
#include "core/mesh/quadric_simplification.h"
#include "tests/core/shell_fixtures.h"

namespace {

using namespace mq;

TriMesh split_bunny(int splits) {
  TriMesh m = read_mesh(std::string(MESHQUILT_SHARED_DATA) + "/base/stanford_bunny_70k.obj");
  for (int i = 0; i < splits; ++i) m = test::midpoint_split(m);
  return m;
}

void BM_SimplifySplitBunny(benchmark::State& state) {
  const TriMesh base = split_bunny(static_cast<int>(state.range(0)));
  QuadricSimplificationOptions o;
  o.max_error = 2e-4;
  o.max_edge_length = 0.005;
  int faces = 0;
  for (auto _ : state) {
    const QuadricSimplification s = simplify_by_quadrics(base, o);
    faces = s.mesh.num_faces();
    benchmark::DoNotOptimize(s.mesh.F.data());
  }
  state.counters["input_faces"] = static_cast<double>(base.num_faces());
  state.counters["output_faces"] = faces;
  state.counters["input_faces_per_s"] = benchmark::Counter(
      static_cast<double>(base.num_faces()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SimplifySplitBunny)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
