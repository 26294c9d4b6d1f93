// Shell map (paper section 3.2): stretch optimisation of the bunny's shell (full evaluations on
// the best available evaluator), and point location + embedding of 1M points in local
// coordinates through the optimised map, against plain normal displacement.
#include <benchmark/benchmark.h>

#include <memory>
#include <random>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/shell/shell_embedding.h"
#include "core/shell/shell_map.h"
#include "host/tet_stretch_evaluator.h"

namespace mq {
namespace {

TriMesh bunny() { return read_mesh(std::string(MESHQUILT_SHARED_DATA) + "/base/bunny_igl_7k.off"); }

ShellMapOptions options(const TriMesh& m) {
  ShellMapOptions o;
  o.height = 0.02 * bounding_box(m.V, m.F).extent().norm();
  return o;
}

void BM_ShellMapBuild(benchmark::State& state) {
  const TriMesh m = bunny();
  for (auto _ : state) benchmark::DoNotOptimize(ShellMap(m.V, m.F, options(m)).height());
}
BENCHMARK(BM_ShellMapBuild)->Unit(benchmark::kMillisecond);

void BM_ShellMapOptimize(benchmark::State& state) {
  const TriMesh m = bunny();
  const ShellMap built(m.V, m.F, options(m));
  auto evaluator = make_tet_stretch_evaluator(Device::Auto);
  ShellOptimizeReport r;
  for (auto _ : state) {
    ShellMap map = built;
    r = map.optimize(*evaluator);
  }
  state.counters["before"] = r.stretch_before;
  state.counters["after"] = r.stretch_after;
  state.counters["sweeps"] = r.sweeps;
  state.SetLabel(evaluator->name());
}
BENCHMARK(BM_ShellMapOptimize)->Unit(benchmark::kMillisecond);

struct Embedded {
  std::unique_ptr<ShellMap> map;
  LocalCoordinates points;
};

const Embedded& embedded() {
  static const Embedded e = [] {
    Embedded x;
    const TriMesh m = bunny();
    x.map = std::make_unique<ShellMap>(m.V, m.F, options(m));
    TetStretchCpu cpu;
    x.map->optimize(cpu);
    const int n = 1000000;
    std::mt19937_64 rng(3);
    auto unit = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    x.points.face.resize(n);
    x.points.bary.resize(n, 3);
    x.points.height.resize(n);
    for (int i = 0; i < n; ++i) {
      x.points.face(i) = static_cast<int>(rng() % static_cast<std::uint64_t>(m.F.rows()));
      double u = unit(), v = unit();
      if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
      x.points.bary.row(i) << 1.0 - u - v, u, v;
      x.points.height(i) = unit() * x.map->height();
    }
    return x;
  }();
  return e;
}

void BM_ShellEmbedding1M(benchmark::State& state) {
  const Embedded& e = embedded();
  const ShellEmbedding emb(*e.map);
  for (auto _ : state) benchmark::DoNotOptimize(emb.embed(e.points).data());
  state.SetItemsProcessed(state.iterations() * e.points.size());
}
BENCHMARK(BM_ShellEmbedding1M)->Unit(benchmark::kMillisecond);

void BM_ShellEmbeddingSetup(benchmark::State& state) {
  const Embedded& e = embedded();
  for (auto _ : state) benchmark::DoNotOptimize(ShellEmbedding(*e.map).num_texture_tets());
}
BENCHMARK(BM_ShellEmbeddingSetup)->Unit(benchmark::kMillisecond);

void BM_NormalDisplacement1M(benchmark::State& state) {
  const Embedded& e = embedded();
  for (auto _ : state)
    benchmark::DoNotOptimize(
        normal_displacement(e.map->base_vertices(), e.map->faces(), e.points).data());
  state.SetItemsProcessed(state.iterations() * e.points.size());
}
BENCHMARK(BM_NormalDisplacement1M)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mq

BENCHMARK_MAIN();
