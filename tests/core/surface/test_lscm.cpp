#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/surface/lscm.h"
#include "tests/test_support.h"

namespace mq {
namespace {

double unit_random(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// A planar grid with jittered interior vertices, placed in a tilted plane of 3D.
TriMesh tilted_jittered_grid(const Eigen::Matrix3d& R, std::uint64_t seed) {
  TriMesh m = test::plane_grid(2.0, 1.0, 12, 7);
  std::mt19937_64 rng(seed);
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double x = m.V(v, 0), y = m.V(v, 1);
    if (x > 0 && x < 2 && y > 0 && y < 1) {
      m.V(v, 0) += 0.04 * (unit_random(rng) - 0.5);
      m.V(v, 1) += 0.04 * (unit_random(rng) - 0.5);
    }
  }
  for (int v = 0; v < m.num_vertices(); ++v)
    m.V.row(v) = (R * m.V.row(v).transpose() + Vector3d(0.3, -1, 2)).transpose();
  return m;
}

// Hemisphere z >= 0 of radius r: a pole vertex and `rings` latitude rings of `segments`.
TriMesh hemisphere(double r, int rings, int segments) {
  TriMesh m;
  m.V.resize(1 + rings * segments, 3);
  m.V.row(0) << 0, 0, r;
  for (int i = 1; i <= rings; ++i) {
    const double theta = 0.5 * M_PI * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      m.V.row(1 + (i - 1) * segments + j) << r * std::sin(theta) * std::cos(phi),
          r * std::sin(theta) * std::sin(phi), r * std::cos(theta);
    }
  }
  std::vector<Eigen::Vector3i> faces;
  for (int j = 0; j < segments; ++j) faces.emplace_back(0, 1 + j, 1 + (j + 1) % segments);
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = 1 + (i - 1) * segments + j, b = 1 + (i - 1) * segments + (j + 1) % segments;
      const int c = a + segments, d = b + segments;
      faces.emplace_back(a, c, d);
      faces.emplace_back(a, d, b);
    }
  m.F.resize(static_cast<int>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.F.row(static_cast<int>(f)) = faces[f].transpose();
  return m;
}

double uv_area(const MatrixX3i& F, const MatrixX2d& UV) {
  double a = 0;
  for (int f = 0; f < F.rows(); ++f) {
    const Vector2d ab = (UV.row(F(f, 1)) - UV.row(F(f, 0))).transpose();
    const Vector2d ac = (UV.row(F(f, 2)) - UV.row(F(f, 0))).transpose();
    a += 0.5 * (ab.x() * ac.y() - ab.y() * ac.x());
  }
  return a;
}

TEST(Lscm, PlanarPatchIsReproducedUpToASimilarity) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const TriMesh m = tilted_jittered_grid(R, 5);
  const MatrixX2d UV = lscm(m.V, m.F);
  ASSERT_EQ(UV.rows(), m.V.rows());
  // Planar coordinates of the patch, then the best complex-affine map z -> a z + b to UV.
  const Eigen::MatrixXd P = (m.V * R).leftCols(2);  // rows (R^T v)^T, translation irrelevant
  const int n = m.num_vertices();
  Eigen::MatrixXd A(2 * n, 4);
  Eigen::VectorXd b(2 * n);
  for (int i = 0; i < n; ++i) {
    const double x = P(i, 0), y = P(i, 1);
    A.row(2 * i) << x, -y, 1, 0;
    A.row(2 * i + 1) << y, x, 0, 1;
    b(2 * i) = UV(i, 0);
    b(2 * i + 1) = UV(i, 1);
  }
  const Eigen::VectorXd s = A.colPivHouseholderQr().solve(b);
  EXPECT_LT((A * s - b).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(std::hypot(s(0), s(1)), 1.0, 1e-9);  // area-matched: the similarity is a rotation
  const Eigen::VectorXd d = face_area_distortion(m.V, m.F, UV);
  EXPECT_LT(d.maxCoeff(), 1 + 1e-8);
  EXPECT_EQ(count_flipped(m.F, UV), 0);
  // Angles preserved.
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.F(f, k), b1 = m.F(f, (k + 1) % 3), c = m.F(f, (k + 2) % 3);
      const Vector3d e1 = (m.V.row(b1) - m.V.row(a)).transpose();
      const Vector3d e2 = (m.V.row(c) - m.V.row(a)).transpose();
      const Vector2d u1 = (UV.row(b1) - UV.row(a)).transpose();
      const Vector2d u2 = (UV.row(c) - UV.row(a)).transpose();
      const double a3 = std::acos(e1.normalized().dot(e2.normalized()));
      const double a2 = std::acos(u1.normalized().dot(u2.normalized()));
      ASSERT_NEAR(a3, a2, 1e-8);
    }
}

// The grid of tilted_jittered_grid, not jittered, folded by 90 degrees along its vertex column
// x = 1 (the part beyond rises along the plane's normal), like a patch wrapping round the edge
// of a box.
TriMesh folded(const Eigen::Matrix3d& R) {
  TriMesh m = test::plane_grid(2.0, 1.0, 12, 7);
  for (int v = 0; v < m.num_vertices(); ++v)
    m.V.row(v) = (R * m.V.row(v).transpose() + Vector3d(0.3, -1, 2)).transpose();
  for (int v = 0; v < m.num_vertices(); ++v) {
    const Vector3d local = R.transpose() * (m.V.row(v).transpose() - Vector3d(0.3, -1, 2));
    if (local.x() > 1.0) {
      const Vector3d bent(1.0, local.y(), local.x() - 1.0);
      m.V.row(v) = (R * bent + Vector3d(0.3, -1, 2)).transpose();
    }
  }
  return m;
}

// Developable patches (flat or folded) skip the solve and are unfolded isometrically; a patch
// bent 1e-7 out of developable goes through the solve. Both must place the patch the same way
// (same pins, same scale), so their maps agree closely.
TEST(Lscm, DevelopableShortcutAgreesWithTheSolve) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.4, Vector3d(-1, 2, 0.5).normalized()).toRotationMatrix();
  const TriMesh flat = tilted_jittered_grid(R, 9);
  for (const TriMesh& m : {flat, folded(R)}) {
    TriMesh bent = m;
    for (int v = 0; v < bent.num_vertices(); ++v)
      bent.V.row(v) += 1e-7 * std::sin(3.0 * v) * R.col(2).transpose();
    const MatrixX2d A = lscm(m.V, m.F), B = lscm(bent.V, bent.F);
    EXPECT_LT((A - B).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_GT((A - B).cwiseAbs().maxCoeff(), 0.0);  // the bent patch really took the other path
    // The unfolding is an isometry: every edge keeps its length.
    for (int f = 0; f < m.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
        ASSERT_NEAR((A.row(a) - A.row(b)).norm(), (m.V.row(a) - m.V.row(b)).norm(), 1e-9);
      }
    EXPECT_EQ(count_flipped(m.F, A), 0);
  }
}

TEST(Lscm, HemisphereHasNoFlipsAndBoundedDistortion) {
  const TriMesh m = hemisphere(2.0, 12, 40);
  const MatrixX2d UV = lscm(m.V, m.F);
  EXPECT_EQ(count_flipped(m.F, UV), 0);
  const Eigen::VectorXd d = face_area_distortion(m.V, m.F, UV);
  EXPECT_GT(d.maxCoeff(), 1.2);  // a hemisphere cannot be flattened isometrically
  EXPECT_LT(d.maxCoeff(), 4.0);
  EXPECT_NEAR(uv_area(m.F, UV), surface_area(m.V, m.F), 1e-9 * surface_area(m.V, m.F));
}

// The solve assembles the energy as Dirichlet terms plus a boundary area term; this checks,
// with the paper's own per-triangle residual (sqrt(A_T) (grad v - rot90 grad u), written out
// independently here), that the result is its minimiser: the gradient with respect to every
// vertex but the two pins (found where the rescaled map puts them: (0, 0) and (u > 0, 0)) is
// zero to round-off.
TEST(Lscm, MinimisesThePerTriangleConformalResidual) {
  TriMesh m = hemisphere(1.0, 7, 19);
  std::mt19937_64 rng(7);
  for (int v = 0; v < m.num_vertices(); ++v)  // irregular, so no symmetry hides a wrong sign
    m.V.row(v) *= 1.0 + 0.1 * (unit_random(rng) - 0.5);
  const MatrixX2d UV = lscm(m.V, m.F);
  const int n = m.num_vertices();
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(2 * n);
  double scale = 0;
  for (int f = 0; f < m.num_faces(); ++f) {
    const Vector3d P0 = m.V.row(m.F(f, 0)), P1 = m.V.row(m.F(f, 1)), P2 = m.V.row(m.F(f, 2));
    const Vector3d x = (P1 - P0).normalized(), nrm = (P1 - P0).cross(P2 - P0);
    const Vector3d y = nrm.normalized().cross(x);
    const Vector2d p[3] = {Vector2d::Zero(), Vector2d((P1 - P0).dot(x), 0),
                           Vector2d((P2 - P0).dot(x), (P2 - P0).dot(y))};
    const double A = 0.5 * nrm.norm();
    // grad u = sum_j u_j rot90(e_j) / (2A) with e_j = p_{j+2} - p_{j+1}.
    Eigen::Matrix<double, 2, 6> J;  // residual by (u_0, v_0, u_1, v_1, u_2, v_2)
    for (int j = 0; j < 3; ++j) {
      const Vector2d e = p[(j + 2) % 3] - p[(j + 1) % 3], r(-e.y(), e.x());
      const Vector2d grad = r / (2 * A), rot_grad(-grad.y(), grad.x());
      J.col(2 * j) = -std::sqrt(A) * rot_grad;
      J.col(2 * j + 1) = std::sqrt(A) * grad;
    }
    Eigen::Matrix<double, 6, 1> z;
    for (int j = 0; j < 3; ++j) z.segment<2>(2 * j) = UV.row(m.F(f, j)).transpose();
    const Eigen::Matrix<double, 6, 1> g = 2 * J.transpose() * (J * z);
    for (int j = 0; j < 3; ++j) gradient.segment<2>(2 * m.F(f, j)) += g.segment<2>(2 * j);
    scale = std::max(scale, 2 * (J.transpose() * J).norm() * z.norm());
  }
  int pins = 0;
  for (int v = 0; v < n; ++v) {
    if (UV(v, 1) == 0 && UV(v, 0) >= 0) {
      ++pins;
      continue;
    }
    EXPECT_LT(gradient.segment<2>(2 * v).norm(), 1e-10 * scale) << "vertex " << v;
  }
  EXPECT_EQ(pins, 2);
  EXPECT_EQ(count_flipped(m.F, UV), 0);
}

TEST(Lscm, TotalAreaMatchesAndResultIsDeterministic) {
  const TriMesh m = hemisphere(0.5, 6, 17);
  TriMesh s = m;
  s.V.col(2) *= 0.3;  // flattened cap: still a disk
  const MatrixX2d UV = lscm(s.V, s.F);
  EXPECT_NEAR(uv_area(s.F, UV), surface_area(s.V, s.F), 1e-10);
  EXPECT_EQ(UV, lscm(s.V, s.F));
}

TEST(Lscm, SingleTriangleIsExact) {
  MatrixX3d V(3, 3);
  V << 0, 0, 0, 3, 0.5, 1, -0.2, 2, 0.4;
  MatrixX3i F(1, 3);
  F << 0, 1, 2;
  const MatrixX2d UV = lscm(V, F);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR((UV.row((k + 1) % 3) - UV.row(k)).norm(), (V.row((k + 1) % 3) - V.row(k)).norm(),
                1e-12);
  EXPECT_EQ(count_flipped(F, UV), 0);
}

TEST(Lscm, RejectsNonDisks) {
  const TriMesh cube = test::unit_cube();
  EXPECT_THROW(lscm(cube.V, cube.F), TopologyError);
  const TriMesh torus = test::torus(2, 0.5, 12, 8);
  EXPECT_THROW(lscm(torus.V, torus.F), TopologyError);
  // An annulus: the grid without its centre quad.
  TriMesh grid = test::plane_grid(1, 1, 3, 3);
  MatrixX3i annulus(grid.F.rows() - 2, 3);
  for (int f = 0, g = 0; f < grid.F.rows(); ++f)
    if (f / 2 != 4) annulus.row(g++) = grid.F.row(f);
  EXPECT_THROW(lscm(grid.V, annulus), TopologyError);
  // Two disjoint triangles.
  MatrixX3d V2(6, 3);
  V2 << 0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 0, 0, 6, 0, 0, 5, 1, 0;
  MatrixX3i F2(2, 3);
  F2 << 0, 1, 2, 3, 4, 5;
  EXPECT_THROW(lscm(V2, F2), TopologyError);
  // A bow tie: two triangles sharing one vertex.
  MatrixX3d V3(5, 3);
  V3 << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
  MatrixX3i F3(2, 3);
  F3 << 0, 1, 2, 0, 3, 4;
  EXPECT_THROW(lscm(V3, F3), TopologyError);
  // A triangle with a cube glued on at two opposite cube corners (0 and 7): connected, one
  // boundary loop, Euler characteristic 1 + 2 - 2 = 1, but two pinched vertices.
  MatrixX3d V5(9, 3);
  V5.topRows(3) = V3.topRows(3);
  std::vector<int> map(8);
  for (int i = 0, next = 3; i < 8; ++i) {
    map[i] = i == 0 ? 0 : i == 7 ? 1 : next++;
    if (i != 0 && i != 7) V5.row(map[i]) = cube.V.row(i).array() + 5.0;
  }
  MatrixX3i F5(13, 3);
  F5.row(0) << 0, 1, 2;
  for (int f = 0; f < 12; ++f)
    for (int k = 0; k < 3; ++k) F5(1 + f, k) = map[cube.F(f, k)];
  EXPECT_THROW(lscm(V5, F5), TopologyError);
}

TEST(Lscm, RejectsBadInput) {
  TriMesh m = test::plane_grid(1, 1, 2, 2);
  EXPECT_THROW(lscm(m.V, MatrixX3i(0, 3)), InvalidInput);
  TriMesh nan = m;
  nan.V(4, 2) = std::nan("");
  EXPECT_THROW(lscm(nan.V, nan.F), InvalidInput);
  TriMesh bad = m;
  bad.F(0, 0) = 99;
  EXPECT_THROW(lscm(bad.V, bad.F), InvalidInput);
  TriMesh flat = m;
  flat.V.row(4) << 0.25, 0, 0;  // face (0, 1, 4) becomes collinear
  EXPECT_THROW(lscm(flat.V, flat.F), InvalidInput);
  TriMesh unused = m;
  unused.V.conservativeResize(m.V.rows() + 1, 3);
  unused.V.row(m.V.rows()).setZero();
  EXPECT_THROW(lscm(unused.V, unused.F), InvalidInput);
}

TEST(Lscm, CountFlippedAndDistortion) {
  const TriMesh m = test::plane_grid(1, 1, 4, 4);
  MatrixX2d UV = m.V.leftCols(2);
  EXPECT_EQ(count_flipped(m.F, UV), 0);
  EXPECT_NEAR(face_area_distortion(m.V, m.F, UV).maxCoeff(), 1.0, 1e-12);
  UV.col(0) *= -1;
  EXPECT_EQ(count_flipped(m.F, UV), m.F.rows());
  UV.col(0) *= -2;
  EXPECT_NEAR(face_area_distortion(m.V, m.F, UV).minCoeff(), 2.0, 1e-12);
  UV *= 0.25;  // areas x 1/8 of the doubled ones: 2/16
  EXPECT_NEAR(face_area_distortion(m.V, m.F, UV).maxCoeff(), 8.0, 1e-9);
  EXPECT_THROW(face_area_distortion(m.V, m.F, UV.topRows(3)), InvalidInput);
}

}  // namespace
}  // namespace mq
