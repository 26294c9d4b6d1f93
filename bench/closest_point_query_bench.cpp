// ClosestPointQuery throughput on the 70k-face Stanford bunny: 100k closest() and match()
// queries, one by one and batched (TBB), against a brute force over all faces on a subset.
#include <benchmark/benchmark.h>

#include <random>
#include <string>

#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/point_triangle.h"

namespace {

using mq::MatrixX3d;
using mq::Vector3d;

constexpr int kNumQueries = 100000;
constexpr int kNumBrute = 200;

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

mq::TriMesh bunny() {
  return mq::read_mesh(std::string(MESHQUILT_SHARED_DATA) + "/base/stanford_bunny_70k.obj");
}

// Points within a few edge lengths of the surface, except every far_every-th one anywhere in
// the doubled bounding box (0: none); unit normals uniformly random.
void make_queries(const mq::TriMesh& m, int count, int far_every, MatrixX3d& P, MatrixX3d& NP) {
  std::mt19937_64 rng(1);
  const double h = mq::mean_edge_length(m.V, m.F);
  const mq::BoundingBox box = mq::bounding_box(m.V, m.F);
  P.resize(count, 3);
  NP.resize(count, 3);
  for (int i = 0; i < count; ++i) {
    Vector3d n;
    do {
      n = Vector3d(uniform01(rng), uniform01(rng), uniform01(rng)) * 2 - Vector3d::Ones();
    } while (n.norm() < 0.1 || n.norm() > 1);
    NP.row(i) = n.normalized();
    if (far_every == 0 || i % far_every != far_every - 1) {
      const int f = static_cast<int>(rng() % static_cast<uint64_t>(m.F.rows()));
      const double u = uniform01(rng), v = uniform01(rng) * (1 - u);
      P.row(i) = (1 - u - v) * m.V.row(m.F(f, 0)) + u * m.V.row(m.F(f, 1)) +
                 v * m.V.row(m.F(f, 2)) + 3 * h * (uniform01(rng) - 0.5) * n.transpose();
    } else {
      for (int k = 0; k < 3; ++k)
        P(i, k) = box.min(k) + (2 * uniform01(rng) - 0.5) * box.extent()(k);
    }
  }
}

// closest() runs on a mix with 20% far points. match() runs on near points only, the use in
// mesh quilting: for a point at distance d the normal factor of Eq. (1) ranges over [1, 3], so
// every face within ~3d may win and a far point visits most of the mesh.
struct Setup {
  mq::TriMesh mesh = bunny();
  MatrixX3d P, NP;    // mixed
  MatrixX3d Pn, NPn;  // near only
  double lambda = 0;
  Setup() {
    make_queries(mesh, kNumQueries, 5, P, NP);
    make_queries(mesh, kNumQueries, 0, Pn, NPn);
    lambda = 1.0 / mq::mean_edge_length(mesh.V, mesh.F);
  }
};

void BM_Build(benchmark::State& state) {
  const mq::TriMesh m = bunny();
  for (auto _ : state) {
    mq::ClosestPointQuery q(m.V, m.F);
    benchmark::DoNotOptimize(q.num_faces());
  }
}

void BM_ClosestSingle(benchmark::State& state) {
  const Setup s;
  const mq::ClosestPointQuery q(s.mesh.V, s.mesh.F);
  for (auto _ : state)
    for (int i = 0; i < kNumQueries; ++i) {
      const Vector3d p = s.P.row(i);
      benchmark::DoNotOptimize(q.closest(p).face);
    }
  state.SetItemsProcessed(state.iterations() * kNumQueries);
}

void BM_ClosestBatched(benchmark::State& state) {
  const Setup s;
  const mq::ClosestPointQuery q(s.mesh.V, s.mesh.F);
  for (auto _ : state) benchmark::DoNotOptimize(q.closest(s.P).data());
  state.SetItemsProcessed(state.iterations() * kNumQueries);
}

void BM_MatchSingle(benchmark::State& state) {
  const Setup s;
  const mq::ClosestPointQuery q(s.mesh.V, s.mesh.F);
  for (auto _ : state)
    for (int i = 0; i < kNumQueries; ++i) {
      const Vector3d p = s.Pn.row(i), n = s.NPn.row(i);
      benchmark::DoNotOptimize(q.match(p, n, s.lambda).face);
    }
  state.SetItemsProcessed(state.iterations() * kNumQueries);
}

void BM_MatchBatched(benchmark::State& state) {
  const Setup s;
  const mq::ClosestPointQuery q(s.mesh.V, s.mesh.F);
  for (auto _ : state) benchmark::DoNotOptimize(q.match(s.Pn, s.NPn, s.lambda).data());
  state.SetItemsProcessed(state.iterations() * kNumQueries);
}

// Reference: every face tested for each of kNumBrute points (items = queries).
void BM_ClosestBruteForce(benchmark::State& state) {
  const Setup s;
  const MatrixX3d& V = s.mesh.V;
  const mq::MatrixX3i& F = s.mesh.F;
  for (auto _ : state)
    for (int i = 0; i < kNumBrute; ++i) {
      const Vector3d p = s.P.row(i);
      double best = std::numeric_limits<double>::infinity();
      for (int f = 0; f < F.rows(); ++f) {
        const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
        best = std::min(best, mq::point_triangle_squared_distance<double>(p, a, b, c));
      }
      benchmark::DoNotOptimize(best);
    }
  state.SetItemsProcessed(state.iterations() * kNumBrute);
}

// Reference for match(): Eq. (1) over every face for kNumBrute near points.
void BM_MatchBruteForce(benchmark::State& state) {
  const Setup s;
  const mq::ClosestPointQuery q(s.mesh.V, s.mesh.F);  // for the face normals
  const MatrixX3d& V = s.mesh.V;
  const mq::MatrixX3i& F = s.mesh.F;
  for (auto _ : state)
    for (int i = 0; i < kNumBrute; ++i) {
      const Vector3d p = s.Pn.row(i), n = s.NPn.row(i);
      double best = std::numeric_limits<double>::infinity();
      for (int f = 0; f < F.rows(); ++f) {
        const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
        const double d = std::sqrt(mq::point_triangle_squared_distance<double>(p, a, b, c));
        best = std::min(
            best, (1 + s.lambda * d) * (1 + (n - q.face_normals().row(f).transpose()).norm()));
      }
      benchmark::DoNotOptimize(best);
    }
  state.SetItemsProcessed(state.iterations() * kNumBrute);
}

BENCHMARK(BM_Build)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosestSingle)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosestBatched)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MatchSingle)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MatchBatched)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ClosestBruteForce)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MatchBruteForce)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
