// Per-tet shell-map stretch (paper section 3.2, Eq. 8): OpenCL kernel vs TBB path vs the plain
// reference loop, on the shell of the 70k-face Stanford bunny (3 tets per face, ~208k tets).
// The texture side is jittered per benchmark as the optimisation would move it; the OpenCL
// timing includes the texture upload and the read-back, the shell side staying on the device.
#include <benchmark/benchmark.h>

#include <memory>
#include <random>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/shell/offset_surface.h"
#include "core/shell/shell_tetrahedra.h"
#include "core/shell/tet_stretch.h"
#include "host/opencl_runtime.h"
#include "host/tet_stretch_opencl.h"

namespace mq {
namespace {

StretchProblem make_problem() {
  const TriMesh base =
      read_mesh(std::string(MESHQUILT_SHARED_DATA) + "/base/stanford_bunny_70k.obj");
  OffsetOptions opt;
  opt.height = 0.02 * bounding_box(base.V, base.F).extent().norm();
  const OffsetSurface off = offset_surface(base.V, base.F, opt);
  const TetMesh shell = shell_tetrahedra(base.V, off.V, base.F);
  StretchProblem pb{shell.V, shell.V, shell.T};
  std::mt19937_64 rng(42);
  const double e = 0.05 * opt.height;
  for (Eigen::Index i = 0; i < pb.texture_V.rows(); ++i)
    for (int a = 0; a < 3; ++a)
      pb.texture_V(i, a) += (double(rng() >> 11) * 0x1.0p-53 - 0.5) * 2 * e;
  return pb;
}

const StretchProblem& problem() {
  static const StretchProblem pb = make_problem();
  return pb;
}

void set_counters(benchmark::State& state) {
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * problem().T.rows()));
  state.counters["tets"] = double(problem().T.rows());
}

void BM_TetStretchOpenCL(benchmark::State& state) {
  if (!cl::Runtime::available()) {
    state.SkipWithError("no OpenCL platform");
    return;
  }
  TetStretchOpenCL ocl(std::make_shared<cl::Runtime>());
  benchmark::DoNotOptimize(ocl.per_tet(problem()));  // build + shell upload outside timing
  for (auto _ : state) benchmark::DoNotOptimize(ocl.per_tet(problem()));
  set_counters(state);
}
BENCHMARK(BM_TetStretchOpenCL)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TetStretchTbb(benchmark::State& state) {
  TetStretchCpu cpu;
  for (auto _ : state) benchmark::DoNotOptimize(cpu.per_tet(problem()));
  set_counters(state);
}
BENCHMARK(BM_TetStretchTbb)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TetStretchReference(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(tet_stretch_reference(problem()));
  set_counters(state);
}
BENCHMARK(BM_TetStretchReference)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TotalStretch(benchmark::State& state) {
  const Eigen::VectorXd per = TetStretchCpu().per_tet(problem());
  for (auto _ : state) benchmark::DoNotOptimize(total_stretch(problem(), per));
  set_counters(state);
}
BENCHMARK(BM_TotalStretch)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mq

BENCHMARK_MAIN();
