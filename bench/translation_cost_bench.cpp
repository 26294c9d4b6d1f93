// Translation cost (paper section 2.4, Eqs. 1-3): OpenCL kernel vs TBB path vs brute force.
// Realistic size: ~2,000 output points x 400 offsets against the 11,828-face chain-link swatch.
// items_per_second counts (point, offset) pairs, so the three rates compare directly even
// though brute force runs on a reduced problem.
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/planar/translation_cost.h"
#include "host/opencl_runtime.h"
#include "host/translation_cost_opencl.h"

namespace mq {
namespace {

struct Fixture {
  TriMesh swatch;
  TranslationCostProblem problem;
};

// Output points: every stride-th swatch vertex, jittered and moved; offsets: a 20 x 20 grid of
// whole-cell translations around the true shift (t_z = 0).
// lambda_cells > 0 sets lambda to 1 / (lambda_cells mean edges), as geometry matching does with
// its grid cell (several edges); else lambda stays 1 in swatch units, where the normal factor
// dominates Eq. (1).
Fixture make_fixture(int stride, int offsets_per_axis, double lambda_cells = 0) {
  Fixture fx;
  fx.swatch = read_mesh(std::string(MESHQUILT_SHARED_DATA) + "/swatch/chainlink_half_12k.obj");
  const MatrixX3d N = vertex_normals(fx.swatch.V, fx.swatch.F);
  const double h = mean_edge_length(fx.swatch.V, fx.swatch.F);
  std::mt19937_64 rng(42);
  auto jitter = [&] { return (double(rng() >> 11) * 0x1.0p-53 - 0.5) * 0.4 * h; };
  const int P = (fx.swatch.num_vertices() + stride - 1) / stride;
  const Vector3d shift(3 * h, 2 * h, 0);
  TranslationCostProblem& pb = fx.problem;
  pb.points.resize(P, 3);
  pb.point_normals.resize(P, 3);
  for (int i = 0; i < P; ++i) {
    pb.points.row(i) = fx.swatch.V.row(i * stride) + shift.transpose() +
                       Eigen::RowVector3d(jitter(), jitter(), jitter());
    pb.point_normals.row(i) = N.row(i * stride);
  }
  const int n = offsets_per_axis;
  pb.offsets.resize(n * n, 3);
  const int half = n / 2;  // the grid of offsets centred on the shift
  for (int i = 0; i < n * n; ++i) {
    const int row = i / n;
    pb.offsets.row(i) = shift + Vector3d(h * (i % n - half), h * (row - half), 0);
  }
  if (lambda_cells > 0) pb.lambda = 1.0 / (lambda_cells * h);
  return fx;
}

void set_counters(benchmark::State& state, const TranslationCostProblem& pb, int faces) {
  const double pairs = double(pb.points.rows()) * double(pb.offsets.rows());
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * pairs));
  state.counters["points"] = double(pb.points.rows());
  state.counters["offsets"] = double(pb.offsets.rows());
  state.counters["faces"] = faces;
}

void BM_TranslationCostOpenCL(benchmark::State& state) {
  if (!cl::Runtime::available()) {
    state.SkipWithError("no OpenCL platform");
    return;
  }
  const Fixture fx = make_fixture(3, 20);
  const SwatchFaceTree tree(fx.swatch.V, fx.swatch.F);
  TranslationCostOpenCL ocl(std::make_shared<cl::Runtime>());
  benchmark::DoNotOptimize(ocl.evaluate(tree, fx.problem));  // build + upload outside timing
  for (auto _ : state) benchmark::DoNotOptimize(ocl.evaluate(tree, fx.problem));
  set_counters(state, fx.problem, fx.swatch.num_faces());
}
BENCHMARK(BM_TranslationCostOpenCL)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TranslationCostTbb(benchmark::State& state) {
  const Fixture fx = make_fixture(3, 20);
  const SwatchFaceTree tree(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  for (auto _ : state) benchmark::DoNotOptimize(cpu.evaluate(tree, fx.problem));
  set_counters(state, fx.problem, fx.swatch.num_faces());
}
BENCHMARK(BM_TranslationCostTbb)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same with matching's distance weight (lambda = 1 / cell, the cell about 8 mean edges).
void BM_TranslationCostOpenCLMatchingWeight(benchmark::State& state) {
  if (!cl::Runtime::available()) {
    state.SkipWithError("no OpenCL platform");
    return;
  }
  const Fixture fx = make_fixture(3, 20, 8.0);
  const SwatchFaceTree index(fx.swatch.V, fx.swatch.F);
  TranslationCostOpenCL ocl(std::make_shared<cl::Runtime>());
  benchmark::DoNotOptimize(ocl.evaluate(index, fx.problem));
  for (auto _ : state) benchmark::DoNotOptimize(ocl.evaluate(index, fx.problem));
  set_counters(state, fx.problem, fx.swatch.num_faces());
}
BENCHMARK(BM_TranslationCostOpenCLMatchingWeight)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TranslationCostTbbMatchingWeight(benchmark::State& state) {
  const Fixture fx = make_fixture(3, 20, 8.0);
  const SwatchFaceTree index(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  for (auto _ : state) benchmark::DoNotOptimize(cpu.evaluate(index, fx.problem));
  set_counters(state, fx.problem, fx.swatch.num_faces());
}
BENCHMARK(BM_TranslationCostTbbMatchingWeight)->Unit(benchmark::kMillisecond)->UseRealTime();

// Matching-sized problems, where a launch's fixed cost matters: arguments (stride, offsets per
// axis); (184, 5) is a screening pass (32 points x 25 offsets), (16, 2) a finalist pass (~370
// points x 4 offsets), larger ones where the device starts to pay. The OpenCL evaluator is
// forced onto the device at every size (min_device_pairs = 0).
void small_problem_args(benchmark::internal::Benchmark* b) {
  for (const auto& [stride, n] :
       std::vector<std::pair<int, int>>{{184, 5}, {16, 2}, {48, 6}, {24, 8}, {12, 10}, {6, 12}})
    b->Args({stride, n});
}

void BM_TranslationCostOpenCLSmall(benchmark::State& state) {
  if (!cl::Runtime::available()) {
    state.SkipWithError("no OpenCL platform");
    return;
  }
  const Fixture fx =
      make_fixture(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 8.0);
  const SwatchFaceTree tree(fx.swatch.V, fx.swatch.F);
  TranslationCostOpenCL::Options options;
  options.min_device_pairs = 0;
  TranslationCostOpenCL ocl(std::make_shared<cl::Runtime>(), options);
  benchmark::DoNotOptimize(ocl.evaluate(tree, fx.problem));
  for (auto _ : state) benchmark::DoNotOptimize(ocl.evaluate(tree, fx.problem));
  set_counters(state, fx.problem, fx.swatch.num_faces());
}
BENCHMARK(BM_TranslationCostOpenCLSmall)
    ->Apply(small_problem_args)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

void BM_TranslationCostTbbSmall(benchmark::State& state) {
  const Fixture fx =
      make_fixture(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 8.0);
  const SwatchFaceTree tree(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  for (auto _ : state) benchmark::DoNotOptimize(cpu.evaluate(tree, fx.problem));
  set_counters(state, fx.problem, fx.swatch.num_faces());
}
BENCHMARK(BM_TranslationCostTbbSmall)
    ->Apply(small_problem_args)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

void BM_TranslationCostBruteForceReduced(benchmark::State& state) {
  const Fixture fx = make_fixture(30, 4);  // ~200 points x 16 offsets
  for (auto _ : state)
    benchmark::DoNotOptimize(translation_cost_brute_force(fx.swatch.V, fx.swatch.F, fx.problem));
  set_counters(state, fx.problem, fx.swatch.num_faces());
}
BENCHMARK(BM_TranslationCostBruteForceReduced)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SwatchFaceTreeBuild(benchmark::State& state) {
  const Fixture fx = make_fixture(60, 1);
  for (auto _ : state) {
    SwatchFaceTree tree(fx.swatch.V, fx.swatch.F);
    benchmark::DoNotOptimize(tree.fingerprint());
  }
  state.counters["faces"] = fx.swatch.num_faces();
}
BENCHMARK(BM_SwatchFaceTreeBuild)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mq

BENCHMARK_MAIN();
