#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <cmath>

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
