// Straightest geodesics: straight on a plane, round a cylinder, length kept over a fold.
#include <gtest/gtest.h>

#include "core/mesh/mesh_topology.h"
#include "core/surface/straightest_geodesic.h"
#include "tests/test_support.h"

namespace mq {
namespace {

Vector3d point(const TriMesh& m, int f, const Vector3d& b) {
  return b(0) * m.V.row(m.F(f, 0)).transpose() + b(1) * m.V.row(m.F(f, 1)).transpose() +
         b(2) * m.V.row(m.F(f, 2)).transpose();
}

// A face containing p (on a plane z = const or a cylinder), with p's barycentric coordinates.
int locate(const TriMesh& m, const Vector3d& p, Vector3d& b) {
  for (int f = 0; f < m.num_faces(); ++f) {
    const Vector3d a = m.V.row(m.F(f, 0)), c1 = m.V.row(m.F(f, 1)), c2 = m.V.row(m.F(f, 2));
    const Vector3d e0 = c1 - a, e1 = c2 - a, d = p - a, n = e0.cross(e1);
    if (std::abs(d.dot(n.normalized())) > 1e-3) continue;
    const double den = n.squaredNorm();
    const double v = e0.cross(d).dot(n) / den, u = d.cross(e1).dot(n) / den;
    if (u >= -1e-12 && v >= -1e-12 && u + v <= 1 + 1e-12) {
      b = Vector3d(1 - u - v, u, v);
      return f;
    }
  }
  return -1;
}

TEST(StraightestGeodesic, StraightLineOnAPlane) {
  const TriMesh m = test::plane_grid(4, 4, 9, 7);
  const MatrixX3i TT = face_adjacency(edge_topology(m.F, m.num_vertices()));
  Vector3d b;
  int f = locate(m, Vector3d(0.3, 0.4, 0), b);
  ASSERT_GE(f, 0);
  ASSERT_TRUE(straightest_walk(m.V, m.F, TT, f, b, Vector3d(2.5, 1.7, 0)));
  EXPECT_LT((point(m, f, b) - Vector3d(2.8, 2.1, 0)).norm(), 1e-9);
  EXPECT_GE(b.minCoeff(), 0.0);
  EXPECT_NEAR(b.sum(), 1.0, 1e-12);
}

TEST(StraightestGeodesic, LeavingThroughABoundaryFails) {
  const TriMesh m = test::plane_grid(1, 1, 4, 4);
  const MatrixX3i TT = face_adjacency(edge_topology(m.F, m.num_vertices()));
  Vector3d b;
  int f = locate(m, Vector3d(0.5, 0.5, 0), b);
  ASSERT_GE(f, 0);
  EXPECT_FALSE(straightest_walk(m.V, m.F, TT, f, b, Vector3d(2, 0, 0)));
}

TEST(StraightestGeodesic, AroundACylinderAndAlongIt) {
  const double r = 1.0;
  const TriMesh m = test::open_cylinder(r, 4.0, 64, 16);
  const MatrixX3i TT = face_adjacency(edge_topology(m.F, m.num_vertices()));
  Vector3d b;
  const int f0 = locate(m, Vector3d(r, 0, 1.0), b);
  ASSERT_GE(f0, 0);
  // Along the axis: a straight line on the surface.
  int f = f0;
  Vector3d bb = b;
  ASSERT_TRUE(straightest_walk(m.V, m.F, TT, f, bb, Vector3d(0, 0, 2.0)));
  EXPECT_LT((point(m, f, bb) - Vector3d(r, 0, 3.0)).norm(), 1e-9);
  // Round it, along the 64-gon's first side: once round its perimeter comes back to the start.
  const double perimeter = 64 * 2 * r * std::sin(kTwoPi / 128);
  const Vector3d side = Vector3d(std::cos(kTwoPi / 64) - 1, std::sin(kTwoPi / 64), 0).normalized();
  f = f0;
  bb = b;
  ASSERT_TRUE(straightest_walk(m.V, m.F, TT, f, bb, perimeter * side));
  EXPECT_LT((point(m, f, bb) - Vector3d(r, 0, 1.0)).norm(), 1e-6);
}

TEST(StraightestGeodesic, KeepsItsLengthOverAFold) {
  // Two squares meeting at a right angle along x = 1 (a box's edge).
  TriMesh m;
  m.V.resize(6, 3);
  m.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, -1, 1, 1, -1;
  m.F.resize(4, 3);
  m.F << 0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2;
  const MatrixX3i TT = face_adjacency(edge_topology(m.F, m.num_vertices()));
  Vector3d b;
  int f = locate(m, Vector3d(0.5, 0.25, 0), b);
  ASSERT_GE(f, 0);
  // Towards the edge at 45 degrees: 0.5 to reach it, 0.3 more down the other side.
  const Vector3d t = 0.8 * Vector3d(1, 1, 0).normalized();
  ASSERT_TRUE(straightest_walk(m.V, m.F, TT, f, b, t));
  const double s = 0.8 / std::sqrt(2.0);
  EXPECT_LT((point(m, f, b) - Vector3d(1, 0.25 + s, -(s - 0.5))).norm(), 1e-9);
}

}  // namespace
}  // namespace mq
