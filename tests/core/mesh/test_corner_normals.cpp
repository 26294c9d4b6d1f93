#include <gtest/gtest.h>

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
