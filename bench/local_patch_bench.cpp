// Local patches on a curved base (section 3.1): growing and flattening 1000 patches of about
// 500 faces on the 70k-face Stanford bunny with one LocalPatchBuilder; also the one-off LSCM of
// a 500-face patch and the builder setup, to see where the time goes.
#include <benchmark/benchmark.h>

#include <string>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/surface/local_patch.h"
#include "core/surface/lscm.h"

namespace {

using namespace mq;

// Loaded by each benchmark outside its timed loop.
TriMesh bunny70k() {
  return read_mesh(std::string(MESHQUILT_SHARED_DATA) + "/base/stanford_bunny_70k.obj");
}

LocalPatchOptions patch_options(const TriMesh& base, double faces) {
  LocalPatchOptions o;
  o.max_area = faces * surface_area(base.V, base.F) / base.num_faces();
  return o;
}

void BM_Grow1000Patches(benchmark::State& state) {
  const TriMesh base = bunny70k();
  LocalPatchBuilder builder(base);
  const LocalPatchOptions o = patch_options(base, 500);
  double faces = 0, shrinks = 0;
  for (auto _ : state) {
    faces = shrinks = 0;
    for (int i = 0; i < 1000; ++i) {
      const int seed = static_cast<int>((static_cast<long long>(i) * 7919 + 13) % base.num_faces());
      const LocalPatch p = builder.grow(seed, o);
      faces += static_cast<double>(p.faces.size());
      shrinks += p.shrink_steps;
      benchmark::DoNotOptimize(p.uv.data());
    }
  }
  state.counters["mean_faces"] = faces / 1000;
  state.counters["shrink_steps"] = shrinks;
  state.counters["patches_per_s"] =
      benchmark::Counter(1000, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Grow1000Patches)->Unit(benchmark::kMillisecond);

void BM_LscmOf500FacePatch(benchmark::State& state) {
  const TriMesh base = bunny70k();
  LocalPatchBuilder builder(base);
  const LocalPatch p = builder.grow(12345, patch_options(base, 500));
  for (auto _ : state) benchmark::DoNotOptimize(lscm(p.mesh.V, p.mesh.F).data());
  state.counters["faces"] = static_cast<double>(p.faces.size());
}
BENCHMARK(BM_LscmOf500FacePatch)->Unit(benchmark::kMicrosecond);

// LSCM of one patch of about N faces: how the cost of a patch grows with the faces it holds (a
// finer base gives a patch of the same area more faces; issue 14's 1M-face base).
void BM_LscmOfPatch(benchmark::State& state) {
  const TriMesh base = bunny70k();
  LocalPatchBuilder builder(base);
  const LocalPatch p =
      builder.grow(12345, patch_options(base, static_cast<double>(state.range(0))));
  for (auto _ : state) benchmark::DoNotOptimize(lscm(p.mesh.V, p.mesh.F).data());
  state.counters["faces"] = static_cast<double>(p.faces.size());
  state.counters["us_per_face"] = benchmark::Counter(
      static_cast<double>(p.faces.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LscmOfPatch)
    ->Arg(500)
    ->Arg(2000)
    ->Arg(8000)
    ->Arg(24000)
    ->Unit(benchmark::kMillisecond);

void BM_BuilderSetup(benchmark::State& state) {
  const TriMesh base = bunny70k();
  for (auto _ : state) {
    LocalPatchBuilder builder(base);
    benchmark::DoNotOptimize(&builder);
  }
}
BENCHMARK(BM_BuilderSetup)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
