#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/point_triangle.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Uniform in [0, 1) from the raw engine output (portable across standard libraries).
using test::uniform;
using test::uniform01;

Vector3d random_unit(std::mt19937_64& rng) {
  for (;;) {
    const Vector3d v(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    const double n = v.norm();
    if (n > 0.1 && n <= 1.0) return v / n;
  }
}

// num_near points scattered within a couple of edge lengths of the surface (both sides), then
// num_far points in the bounding box enlarged by its extent on every side.
MatrixX3d random_queries(const MatrixX3d& V, const MatrixX3i& F, int num_near, int num_far,
                         uint64_t seed) {
  std::mt19937_64 rng(seed);
  const MatrixX3d FN = face_normals(V, F);
  const double h = mean_edge_length(V, F);
  const BoundingBox box = bounding_box(V, F);
  MatrixX3d P(num_near + num_far, 3);
  for (int i = 0; i < num_near; ++i) {
    const int f = static_cast<int>(rng() % static_cast<uint64_t>(F.rows()));
    double u = uniform01(rng), v = uniform01(rng);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const Vector3d on = (1 - u - v) * V.row(F(f, 0)) + u * V.row(F(f, 1)) + v * V.row(F(f, 2));
    P.row(i) = on.transpose() + uniform(rng, -2, 2) * h * FN.row(f) +
               0.3 * h * random_unit(rng).transpose();
  }
  for (int i = num_near; i < P.rows(); ++i)
    for (int k = 0; k < 3; ++k)
      P(i, k) = uniform(rng, box.min(k) - box.extent()(k), box.max(k) + box.extent()(k));
  return P;
}

struct BruteHit {
  int face = -1;
  double cost = kInf;
};

// Distance from p to face f, computed the obvious way.
double face_distance(const MatrixX3d& V, const MatrixX3i& F, int f, const Vector3d& p) {
  const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  const Vector3d w = closest_point_barycentric<double>(p, a, b, c);
  return (p - (w(0) * a + w(1) * b + w(2) * c)).norm();
}

double face_cost(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& FN, int f,
                 const Vector3d& p, const Vector3d& n, double lambda) {
  return (1 + lambda * face_distance(V, F, f, p)) * (1 + (n - FN.row(f).transpose()).norm());
}

// Brute force over all faces within max_radius: closest (match == false) or Eq. (1).
BruteHit brute_force(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& FN, const Vector3d& p,
                     const Vector3d* n, double lambda, double max_radius) {
  BruteHit best;
  for (int f = 0; f < F.rows(); ++f) {
    const double d = face_distance(V, F, f, p);
    if (d > max_radius) continue;
    const double cost = n ? face_cost(V, F, FN, f, p, *n, lambda) : d;
    if (cost < best.cost) best = {f, cost};
  }
  return best;
}

// The hit agrees with the brute-force optimum: same cost (to 1e-9 relative) and the face is the
// brute-force one or scores equally; point and barycentric are consistent with the face.
void expect_matches_brute(const ClosestPointQuery& q, const ClosestPointHit& hit,
                          const BruteHit& brute, const Vector3d& p, const Vector3d* n,
                          double lambda, const std::string& where) {
  const MatrixX3d& V = q.vertices();
  const MatrixX3i& F = q.faces();
  ASSERT_EQ(hit.face < 0, brute.face < 0) << where;
  if (brute.face < 0) return;
  EXPECT_NEAR(hit.cost, brute.cost, 1e-9 * std::max(1.0, brute.cost)) << where;
  if (hit.face != brute.face) {
    const double c = n ? face_cost(V, F, q.face_normals(), hit.face, p, *n, lambda)
                       : face_distance(V, F, hit.face, p);
    EXPECT_NEAR(c, brute.cost, 1e-12 * std::max(1.0, brute.cost)) << where;
  }
  EXPECT_NEAR(hit.barycentric.sum(), 1.0, 1e-12) << where;
  EXPECT_GE(hit.barycentric.minCoeff(), 0.0) << where;
  const Vector3d point = hit.barycentric(0) * V.row(F(hit.face, 0)) +
                         hit.barycentric(1) * V.row(F(hit.face, 1)) +
                         hit.barycentric(2) * V.row(F(hit.face, 2));
  EXPECT_LT((point - hit.point).norm(), 1e-12 * (1 + point.norm())) << where;
  EXPECT_NEAR((hit.point - p).norm(), hit.distance, 1e-12 * (1 + hit.distance)) << where;
}

void expect_identical(const std::vector<ClosestPointHit>& a,
                      const std::vector<ClosestPointHit>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].face, b[i].face) << i;
    if (a[i].face < 0) continue;
    EXPECT_EQ(a[i].distance, b[i].distance) << i;
    EXPECT_EQ(a[i].cost, b[i].cost) << i;
    EXPECT_EQ(a[i].point, b[i].point) << i;
    EXPECT_EQ(a[i].barycentric, b[i].barycentric) << i;
  }
}

class RealMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(RealMesh, ClosestMatchesBruteForce) {
  const TriMesh m = read_mesh(test::shared_data(GetParam()));
  const ClosestPointQuery q(m.V, m.F);
  ASSERT_EQ(q.num_faces(), m.num_faces());
  const MatrixX3d P = random_queries(m.V, m.F, 1500, 500, 7);
  const std::vector<ClosestPointHit> hits = q.closest(P);
  int exact_face = 0;
  for (int i = 0; i < P.rows(); ++i) {
    const Vector3d p = P.row(i);
    const BruteHit b = brute_force(m.V, m.F, q.face_normals(), p, nullptr, 0, kInf);
    expect_matches_brute(q, hits[i], b, p, nullptr, 0, "query " + std::to_string(i));
    EXPECT_EQ(hits[i].distance, hits[i].cost);
    exact_face += hits[i].face == b.face;
  }
  // Every query has a hit when the radius is unbounded; ties are rare off the surface.
  EXPECT_GE(exact_face, P.rows() * 99 / 100);
}

TEST_P(RealMesh, MatchMatchesBruteForce) {
  const TriMesh m = read_mesh(test::shared_data(GetParam()));
  const ClosestPointQuery q(m.V, m.F);
  const double h = mean_edge_length(m.V, m.F);
  const MatrixX3d P = random_queries(m.V, m.F, 600, 200, 11);
  std::mt19937_64 rng(12);
  MatrixX3d NP(P.rows(), 3);
  for (int i = 0; i < P.rows(); ++i) NP.row(i) = random_unit(rng);
  // lambda in units of inverse length: distance dominates (10/h), balanced (1/h), normal
  // dominates (0.01/h), and the plain paper default 1.
  for (const double lambda : {10.0 / h, 1.0 / h, 0.01 / h, 1.0}) {
    const std::vector<ClosestPointHit> hits = q.match(P, NP, lambda);
    for (int i = 0; i < P.rows(); i += 2) {  // half the points keeps the brute force fast
      const Vector3d p = P.row(i), n = NP.row(i);
      const BruteHit b = brute_force(m.V, m.F, q.face_normals(), p, &n, lambda, kInf);
      expect_matches_brute(q, hits[i], b, p, &n, lambda,
                           "query " + std::to_string(i) + " lambda " + std::to_string(lambda));
    }
  }
}

TEST_P(RealMesh, RadiusIsInclusiveAndExcludesFartherFaces) {
  const TriMesh m = read_mesh(test::shared_data(GetParam()));
  const ClosestPointQuery q(m.V, m.F);
  const MatrixX3d P = random_queries(m.V, m.F, 150, 50, 3);
  std::mt19937_64 rng(4);
  int misses = 0;
  for (int i = 0; i < P.rows(); ++i) {
    const Vector3d p = P.row(i);
    const ClosestPointHit full = q.closest(p);
    ASSERT_GE(full.face, 0);
    // Exactly at the distance: still found (inclusive), just below: nothing.
    EXPECT_EQ(q.closest(p, full.distance).face, full.face) << i;
    const ClosestPointHit below = q.closest(p, std::nextafter(full.distance, 0.0));
    EXPECT_EQ(below.face, -1) << i;
    EXPECT_EQ(below.distance, kInf);
    misses += below.face < 0;
    // match() restricted to a random radius agrees with the restricted brute force.
    const double r = uniform(rng, 0.5, 3.0) * full.distance;
    const Vector3d n = random_unit(rng);
    const ClosestPointHit hit = q.match(p, n, 1.0, r);
    const BruteHit b = brute_force(m.V, m.F, q.face_normals(), p, &n, 1.0, r);
    expect_matches_brute(q, hit, b, p, &n, 1.0, "query " + std::to_string(i));
    if (hit.face >= 0) {
      EXPECT_LE(hit.distance, r);
    }
  }
  EXPECT_EQ(misses, P.rows());
}

INSTANTIATE_TEST_SUITE_P(ClosestPointQuery, RealMesh,
                         ::testing::Values("base/bunny_igl_7k.off",
                                           "swatch/chainlink_half_12k.obj"));

TEST(ClosestPointQuery, FarFromOriginStillExact) {
  // Float rounding of coordinates near 1e4 is ~1e-3 relative to a unit-size mesh: the pruning
  // slack must scale with coordinate magnitude, not only with the mesh extent.
  TriMesh m = read_mesh(test::shared_data("base/bunny_igl_7k.off"));
  const BoundingBox box = bounding_box(m.V, m.F);
  m.V = (m.V.rowwise() - box.min.transpose()) / box.extent().maxCoeff();
  m.V.rowwise() += Vector3d(1e4, -2e4, 3e4).transpose();
  const ClosestPointQuery q(m.V, m.F);
  const MatrixX3d P = random_queries(m.V, m.F, 400, 100, 5);
  const std::vector<ClosestPointHit> hits = q.closest(P);
  for (int i = 0; i < P.rows(); ++i) {
    const Vector3d p = P.row(i);
    const BruteHit b = brute_force(m.V, m.F, q.face_normals(), p, nullptr, 0, kInf);
    expect_matches_brute(q, hits[i], b, p, nullptr, 0, "query " + std::to_string(i));
  }
}

TEST(ClosestPointQuery, ExactTiesGoToSmallestFaceIndex) {
  const TriMesh cube = test::unit_cube();
  const ClosestPointQuery q(cube.V, cube.F);
  // The centre is 0.5 from all 12 faces.
  const ClosestPointHit centre = q.closest(Vector3d(0.5, 0.5, 0.5));
  EXPECT_EQ(centre.face, 0);
  EXPECT_EQ(centre.distance, 0.5);
  // Beyond corner 0, faces 0, 4 and 8 share the closest point (vertex 0); so does the normal
  // term for the diagonal normal, whose distance to each axis normal is the same.
  const Vector3d corner(-1, -1, -1);
  const ClosestPointHit c = q.closest(corner);
  EXPECT_EQ(c.face, 0);
  EXPECT_EQ(c.point, Vector3d::Zero());
  EXPECT_EQ(q.match(corner, Vector3d(-1, -1, -1), 1.0).face, 0);
  // Beyond corner 7 (faces 5, 7, 11 hold vertex 7; 3, 5 share it in the y=1 pair).
  const ClosestPointHit c7 = q.closest(Vector3d(2, 2, 2));
  EXPECT_EQ(c7.point, Vector3d::Ones());
  int smallest = cube.num_faces();
  for (int f = 0; f < cube.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      if (cube.F(f, k) == 7) smallest = std::min(smallest, f);
  EXPECT_EQ(c7.face, smallest);
  // The normal decides between equally distant faces: +x normal at the centre picks x = 1.
  const ClosestPointHit side = q.match(Vector3d(0.5, 0.5, 0.5), Vector3d(3, 0, 0), 1.0);
  EXPECT_EQ(side.face, 10);
  EXPECT_DOUBLE_EQ(side.cost, 1.5);
}

TEST(ClosestPointQuery, MatchWithZeroLambdaRanksByNormalOnly) {
  const TriMesh t = test::torus(2.0, 0.5, 24, 12);
  const ClosestPointQuery q(t.V, t.F);
  const Vector3d n = Vector3d(0.3, -0.2, 0.9).normalized();
  const ClosestPointHit hit = q.match(Vector3d(10, 10, 10), n, 0.0);
  const BruteHit b = brute_force(t.V, t.F, q.face_normals(), Vector3d(10, 10, 10), &n, 0.0, kInf);
  EXPECT_EQ(hit.face, b.face);
  EXPECT_EQ(hit.cost, b.cost);
  EXPECT_EQ(q.match(Vector3d(10, 10, 10), n, 0.0, 1.0).face, -1);  // nothing within radius 1
}

TEST(ClosestPointQuery, BatchedEqualsSingleAndIndependentOfThreadCount) {
  const TriMesh m = read_mesh(test::shared_data("base/bunny_igl_7k.off"));
  const ClosestPointQuery q(m.V, m.F);
  const MatrixX3d P = random_queries(m.V, m.F, 1500, 500, 21);
  std::mt19937_64 rng(22);
  MatrixX3d NP(P.rows(), 3);
  for (int i = 0; i < P.rows(); ++i) NP.row(i) = 2.5 * random_unit(rng);  // not unit on purpose
  const double r = 2 * mean_edge_length(m.V, m.F);
  const double lambda = 1 / mean_edge_length(m.V, m.F);

  std::vector<ClosestPointHit> single_c, single_m, single_cr;
  for (int i = 0; i < P.rows(); ++i) {
    const Vector3d p = P.row(i), n = NP.row(i);
    single_c.push_back(q.closest(p));
    single_cr.push_back(q.closest(p, r));
    single_m.push_back(q.match(p, n, lambda));
  }
  int restricted_misses = 0;
  for (const auto& h : single_cr) restricted_misses += h.face < 0;
  EXPECT_GT(restricted_misses, 0);  // the far points are beyond r
  EXPECT_LT(restricted_misses, P.rows());

  for (const int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      expect_identical(q.closest(P), single_c);
      expect_identical(q.closest(P, r), single_cr);
      expect_identical(q.match(P, NP, lambda), single_m);
    });
  }
  const Eigen::VectorXd D = point_mesh_distance(P, m.V, m.F);
  ASSERT_EQ(D.size(), P.rows());
  for (int i = 0; i < P.rows(); ++i) EXPECT_EQ(D(i), single_c[i].distance);
}

TEST(ClosestPointQuery, SharedDeviceAndMove) {
  const EmbreeDevice device;
  const TriMesh cube = test::unit_cube();
  const TriMesh torus = test::torus(2.0, 0.5, 12, 6);
  ClosestPointQuery a(device, cube.V, cube.F);
  const ClosestPointQuery b(device, torus.V, torus.F);
  EXPECT_DOUBLE_EQ(a.closest(Vector3d(0.5, 0.5, 3)).distance, 2.0);
  // The inner equator is a 12-gon of circumradius 1.5: its edges come closer to the axis.
  const double inner = b.closest(Vector3d(0, 0, 0)).distance;
  EXPECT_LE(inner, 1.5);
  EXPECT_GE(inner, 1.5 * std::cos(M_PI / 12) - 1e-12);
  ClosestPointQuery moved(std::move(a));
  EXPECT_DOUBLE_EQ(moved.closest(Vector3d(0.5, 0.5, 3)).distance, 2.0);
  EXPECT_THROW(a.closest(Vector3d(0, 0, 0)), InternalError);  // NOLINT(bugprone-use-after-move)
  a = std::move(moved);
  EXPECT_DOUBLE_EQ(a.closest(Vector3d(0.5, 0.5, -1)).distance, 1.0);
  EXPECT_EQ(a.num_faces(), 12);
}

TEST(ClosestPointQuery, InvalidInputThrows) {
  const TriMesh cube = test::unit_cube();
  EXPECT_THROW(ClosestPointQuery(cube.V, MatrixX3i(0, 3)), InvalidInput);
  MatrixX3d nan_v = cube.V;
  nan_v(3, 1) = std::nan("");
  EXPECT_THROW(ClosestPointQuery(nan_v, cube.F), InvalidInput);
  MatrixX3d inf_v = cube.V;
  inf_v(0, 0) = kInf;
  EXPECT_THROW(ClosestPointQuery(inf_v, cube.F), InvalidInput);
  MatrixX3i bad_f = cube.F;
  bad_f(5, 2) = 8;
  EXPECT_THROW(ClosestPointQuery(cube.V, bad_f), InvalidInput);
  bad_f(5, 2) = -1;
  EXPECT_THROW(ClosestPointQuery(cube.V, bad_f), InvalidInput);

  const ClosestPointQuery q(cube.V, cube.F);
  const Vector3d p(0.2, 0.3, 2), nan_p(0, std::nan(""), 0);
  EXPECT_THROW(q.closest(nan_p), InvalidInput);
  EXPECT_THROW(q.closest(p, -1.0), InvalidInput);
  EXPECT_THROW(q.closest(p, std::nan("")), InvalidInput);
  EXPECT_THROW(q.match(p, Vector3d::Zero()), InvalidInput);
  EXPECT_THROW(q.match(p, Vector3d(0, 0, kInf)), InvalidInput);
  EXPECT_THROW(q.match(p, Vector3d::UnitZ(), -1.0), InvalidInput);
  EXPECT_THROW(q.match(p, Vector3d::UnitZ(), kInf), InvalidInput);
  MatrixX3d P(2, 3);
  P << 0, 0, 0, 1, std::nan(""), 0;
  EXPECT_THROW(q.closest(P), InvalidInput);
  EXPECT_THROW(q.match(MatrixX3d(MatrixX3d::Zero(2, 3)), MatrixX3d(MatrixX3d::Ones(3, 3))),
               InvalidInput);
  MatrixX3d NP = MatrixX3d::Ones(2, 3);
  NP.row(1).setZero();
  EXPECT_THROW(q.match(MatrixX3d(MatrixX3d::Zero(2, 3)), NP), InvalidInput);
  // Radius zero is valid: only points on the surface hit.
  EXPECT_EQ(q.closest(p, 0.0).face, -1);
  EXPECT_EQ(q.closest(Vector3d(1, 1, 1), 0.0).distance, 0.0);
}

}  // namespace
}  // namespace mq
