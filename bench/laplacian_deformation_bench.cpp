// Element deformation (section 2.6) on a typical merge workload: about 100 ring elements with
// about 100 constraints each, solved by deform_elements with 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <random>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/laplacian_deformation.h"

namespace {

using namespace mq;

double unit_random(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Closed torus ring of n x m vertices around the z axis, centred at c.
TriMesh ring(int n, int m, const Vector3d& c) {
  TriMesh t;
  t.V.resize(n * m, 3);
  t.F.resize(2 * n * m, 3);
  const double pi = std::acos(-1.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * pi * i / n, v = 2 * pi * j / m;
      t.V.row(i * m + j) << c.x() + (2 + 0.5 * std::cos(v)) * std::cos(u),
          c.y() + (2 + 0.5 * std::cos(v)) * std::sin(u), c.z() + 0.5 * std::sin(v);
      const int a = i * m + j, b = ((i + 1) % n) * m + j, d = i * m + (j + 1) % m,
                e = ((i + 1) % n) * m + (j + 1) % m;
      t.F.row(2 * (i * m + j)) << a, b, e;
      t.F.row(2 * (i * m + j) + 1) << a, e, d;
    }
  return t;
}

// Barycentric constraints on random faces pulled by up to 0.2 mean edge lengths (seeded).
std::vector<DeformationJob> make_jobs(const std::vector<TriMesh>& meshes, int num_jobs,
                                      int num_constraints) {
  std::mt19937_64 rng(42);
  std::vector<DeformationJob> jobs;
  for (int j = 0; j < num_jobs; ++j) {
    const TriMesh& m = meshes[j % meshes.size()];
    const double h = mean_edge_length(m.V, m.F);
    DeformationJob job{&m.V, &m.F, {}};
    for (int c = 0; c < num_constraints; ++c) {
      const int f = static_cast<int>(rng() % static_cast<uint64_t>(m.num_faces()));
      const double a = unit_random(rng), b = (1 - a) * unit_random(rng);
      const Vector3d w(a, b, 1 - a - b);
      Vector3d p = Vector3d::Zero();
      for (int k = 0; k < 3; ++k) p += w[k] * m.V.row(m.F(f, k)).transpose();
      const Vector3d jitter(unit_random(rng) - 0.5, unit_random(rng) - 0.5, unit_random(rng) - 0.5);
      job.constraints.push_back(
          LinearConstraint::barycentric(m.F(f, 0), m.F(f, 1), m.F(f, 2), w, p + 0.4 * h * jitter));
    }
    jobs.push_back(std::move(job));
  }
  return jobs;
}

void run_jobs(benchmark::State& state, const std::vector<DeformationJob>& jobs) {
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    arena.execute([&] { benchmark::DoNotOptimize(deform_elements(jobs)); });
  }
  state.counters["elements"] = static_cast<double>(jobs.size());
  state.counters["time_per_element"] = benchmark::Counter(
      static_cast<double>(jobs.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// 100 procedural rings of 1000 vertices (40 x 25), 100 constraints each.
void BM_DeformElements_Rings1000(benchmark::State& state) {
  std::vector<TriMesh> meshes;
  for (int i = 0; i < 10; ++i) meshes.push_back(ring(40, 25, Vector3d(5.0 * i, 0, 0)));
  run_jobs(state, make_jobs(meshes, 100, 100));
}
BENCHMARK(BM_DeformElements_Rings1000)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The 48 real rings of the chain-mail swatch (512 vertices each), twice: 96 jobs.
void BM_DeformElements_ChainmailRings(benchmark::State& state) {
  const TriMesh mail = read_mesh(MESHQUILT_SHARED_DATA "/swatch/chainmail3d_48rings_49k.obj");
  std::vector<int> fc;
  const int nc = connected_components(mail.F, mail.num_vertices(), fc);
  std::vector<TriMesh> meshes;
  for (const std::vector<int>& faces : component_faces(fc, nc))
    meshes.push_back(extract_faces(mail, faces));
  run_jobs(state, make_jobs(meshes, 2 * nc, 100));
}
BENCHMARK(BM_DeformElements_ChainmailRings)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One 1000-vertex element: precomputation (Laplacian, ordering) versus one solve.
void BM_LaplacianDeformer_Precompute(benchmark::State& state) {
  const TriMesh m = ring(40, 25, Vector3d::Zero());
  for (auto _ : state) benchmark::DoNotOptimize(LaplacianDeformer(m.V, m.F));
}
BENCHMARK(BM_LaplacianDeformer_Precompute)->Unit(benchmark::kMicrosecond);

// The same element with its topology taken from a cache (a copy of a swatch element): only
// delta = L V and L^T delta remain.
void BM_LaplacianDeformer_PrecomputeSharedTopology(benchmark::State& state) {
  const TriMesh m = ring(40, 25, Vector3d::Zero());
  LaplacianTopologyCache cache;
  cache.add(m.F, m.num_vertices());
  const auto topology = cache.find(m.F, m.num_vertices());
  for (auto _ : state) {
    benchmark::DoNotOptimize(cache.find(m.F, m.num_vertices()));
    benchmark::DoNotOptimize(LaplacianDeformer(topology, m.V));
  }
}
BENCHMARK(BM_LaplacianDeformer_PrecomputeSharedTopology)->Unit(benchmark::kMicrosecond);

void BM_LaplacianDeformer_Solve(benchmark::State& state) {
  const std::vector<TriMesh> meshes{ring(40, 25, Vector3d::Zero())};
  const std::vector<DeformationJob> jobs = make_jobs(meshes, 1, 100);
  const LaplacianDeformer deformer(meshes[0].V, meshes[0].F);
  for (auto _ : state) benchmark::DoNotOptimize(deformer.solve(jobs[0].constraints));
}
BENCHMARK(BM_LaplacianDeformer_Solve)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
