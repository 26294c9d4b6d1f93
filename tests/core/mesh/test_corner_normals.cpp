#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/corner_normals.h"
#include "core/mesh/geometry_measures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(CornerNormals, CubeCornersKeepTheirFaceNormals) {
  const TriMesh cube = test::unit_cube();
  const CornerNormals c = corner_normals(cube.V, cube.F, 60);
  const MatrixX3d FN = face_normals(cube.V, cube.F);
  // Every corner takes only the faces of its own side: exactly the face normal.
  for (int f = 0; f < cube.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_LT((c.N.row(c.FN(f, k)) - FN.row(f)).norm(), 1e-12) << f << " " << k;
  // Each of the 8 vertices has 3 sides: 24 distinct normals.
  EXPECT_EQ(c.N.rows(), 24);
}

TEST(CornerNormals, SmoothSurfaceHasOneNormalPerVertexEqualToTheVertexNormal) {
  const TriMesh t = test::torus(1.0, 0.3, 48, 16);
  const CornerNormals c = corner_normals(t.V, t.F, 60);
  EXPECT_EQ(c.N.rows(), t.V.rows());
  const MatrixX3d VN = vertex_normals(t.V, t.F);
  for (int f = 0; f < t.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) ASSERT_LT((c.N.row(c.FN(f, k)) - VN.row(t.F(f, k))).norm(), 1e-9);
}

TEST(CornerNormals, ManyVerticesAreNumberedInVertexOrderWhateverTheThreads) {
  // 1,000 cubes (8,000 vertices: the normals are gathered per block of vertices) in a row.
  const TriMesh cube = test::unit_cube();
  TriMesh m;
  m.V.resize(8000, 3);
  m.F.resize(12000, 3);
  for (int c = 0; c < 1000; ++c) {
    // Each turned its own way, so that no two cubes share a normal.
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.001 * c, Vector3d::UnitZ()).toRotationMatrix();
    m.V.middleRows(8 * c, 8) =
        (cube.V * turn.transpose()).rowwise() + Eigen::RowVector3d(2.0 * c, 0, 0);
    m.F.middleRows(12 * c, 12) = cube.F.array() + 8 * c;
  }
  const CornerNormals c = corner_normals(m.V, m.F, 60);
  ASSERT_EQ(c.N.rows(), 24000);
  const MatrixX3d FN = face_normals(m.V, m.F);
  for (int f = 0; f < m.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      // Vertex v's three normals are rows 3v to 3v + 2: numbered in vertex order.
      const int v = m.F(f, k);
      ASSERT_GE(c.FN(f, k), 3 * v);
      ASSERT_LT(c.FN(f, k), 3 * v + 3);
      ASSERT_LT((c.N.row(c.FN(f, k)) - FN.row(f)).norm(), 1e-12);
    }
  CornerNormals one;
  {
    tbb::global_control g(tbb::global_control::max_allowed_parallelism, 1);
    one = corner_normals(m.V, m.F, 60);
  }
  EXPECT_TRUE(one.N == c.N);
  EXPECT_TRUE(one.FN == c.FN);
}

// The rule written out plainly (each corner sums, in face order, the area-weighted normals of
// the faces around its vertex within the crease angle of its own face), against which the
// smooth-fan shortcut must give bitwise the same normals: a bumpy sheet, where some fans are
// smooth and some are not at every angle tried.
TEST(CornerNormals, SmoothFanShortcutGivesTheRuleBitwise) {
  const int n = 40;
  TriMesh m;
  m.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.V.row(j * (n + 1) + i) << i, j, 0.9 * std::sin(1.3 * i) * std::cos(0.7 * j * j);
  m.F.resize(2 * n * n, 3);
  for (int j = 0, f = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      m.F.row(f++) << a, a + 1, a + n + 2;
      m.F.row(f++) << a, a + n + 2, a + n + 1;
    }
  MatrixX3d W(m.num_faces(), 3), U(m.num_faces(), 3);
  for (int f = 0; f < m.num_faces(); ++f) {
    const Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    const Vector3d w = (b - a).cross(c - a);
    W.row(f) = w.transpose();
    U.row(f) = (w / w.norm()).transpose();
  }
  std::vector<std::vector<int>> around(static_cast<size_t>(m.V.rows()));
  for (int f = 0; f < m.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) around[static_cast<size_t>(m.F(f, k))].push_back(f);
  for (const double degrees : {0.0, 5.0, 30.0, 60.0, 120.0, 179.0, 180.0}) {
    const CornerNormals c = corner_normals(m.V, m.F, degrees);
    const double min_cos = degrees >= 180 ? -2.0 : std::cos(degrees * M_PI / 180.0);
    int smooth = 0;
    for (int v = 0; v < m.V.rows(); ++v) {
      std::vector<Vector3d> distinct;
      for (const int f : around[static_cast<size_t>(v)]) {
        Vector3d sum = Vector3d::Zero(), all = Vector3d::Zero();
        for (const int g : around[static_cast<size_t>(v)]) {
          all += W.row(g).transpose();
          if (U.row(f).dot(U.row(g)) >= min_cos) sum += W.row(g).transpose();
        }
        // Not even its own face (a unit normal's dot with itself rounds under 1 at 0 degrees):
        // the vertex's normal.
        if (!(sum.norm() > 0)) sum = all;
        const Vector3d expected = sum.normalized();
        int k = 0;
        while (m.F(f, k) != v) ++k;
        ASSERT_TRUE(c.N.row(c.FN(f, k)).transpose() == expected)
            << degrees << " degrees, vertex " << v << ", face " << f;
        if (std::find(distinct.begin(), distinct.end(), expected) == distinct.end())
          distinct.push_back(expected);
      }
      smooth += distinct.size() == 1;
    }
    // Both kinds of fan occur up to 120 degrees (at 179 and 180 every fan of this sheet is
    // smooth).
    EXPECT_GT(smooth, 0) << degrees;
    if (degrees > 0 && degrees <= 120) {
      EXPECT_LT(smooth, m.V.rows()) << degrees;
    }
  }
}

TEST(CornerNormals, CreaseAngleDecidesAndBadInputIsRefused) {
  const TriMesh cube = test::unit_cube();
  // At 180 degrees every vertex has one normal (the area-weighted average).
  EXPECT_EQ(corner_normals(cube.V, cube.F, 180).N.rows(), 8);
  // At 95 degrees the cube's 90-degree edges are smooth too.
  EXPECT_EQ(corner_normals(cube.V, cube.F, 95).N.rows(), 8);
  EXPECT_THROW(corner_normals(cube.V, cube.F, -1), InvalidInput);
  EXPECT_THROW(corner_normals(cube.V, cube.F, std::nan("")), InvalidInput);
  MatrixX3i bad = cube.F;
  bad(0, 0) = 99;
  EXPECT_THROW(corner_normals(cube.V, bad, 60), InvalidInput);
  // A degenerate face gets its vertex's average, finite and unit.
  TriMesh d = cube;
  d.V.conservativeResize(9, 3);
  d.V.row(8) = d.V.row(0);
  d.F.conservativeResize(13, 3);
  d.F.row(12) << 0, 8, 0;
  const CornerNormals c = corner_normals(d.V, d.F, 60);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c.N.row(c.FN(12, k)).norm(), 1.0, 1e-12);
}

}  // namespace
}  // namespace mq
