#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/shell/signed_height.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(SignedHeight, InsideAndOutsideOfAClosedCube) {
  const TriMesh cube = test::unit_cube();
  const SignedHeight h(cube.V, cube.F);
  // Over a face, an edge and a vertex: the closest feature's pseudo-normal decides the side.
  EXPECT_NEAR(h(Vector3d(0.5, 0.5, 1.2)), 0.2, 1e-12);
  EXPECT_NEAR(h(Vector3d(0.5, 0.5, 0.9)), -0.1, 1e-12);
  EXPECT_NEAR(h(Vector3d(1.1, 0.5, 1.1)), std::sqrt(0.02), 1e-12);  // beyond an edge
  EXPECT_NEAR(h(Vector3d(1.1, 1.1, 1.1)), std::sqrt(0.03), 1e-12);  // beyond a corner
  EXPECT_NEAR(h(Vector3d(0.95, 0.95, 0.95)), -0.05, 1e-12);         // inside, near a corner
  EXPECT_NEAR(h(Vector3d(0.5, 0.5, 0.5)), -0.5, 1e-12);
  EXPECT_EQ(h(Vector3d(0.5, 0.5, 1.0)), 0.0);
  ClosestPointHit hit;
  h(Vector3d(0.2, 0.3, -0.4), &hit);
  EXPECT_NEAR((hit.point - Vector3d(0.2, 0.3, 0)).norm(), 0, 1e-12);
  EXPECT_THROW(h(Vector3d(std::nan(""), 0, 0)), InvalidInput);
}

TEST(SignedHeight, OpenTubeHasAnInsideToo) {
  // An open cylinder of radius 1: inside the tube is under its (outward) surface.
  const TriMesh tube = test::open_cylinder(1.0, 2.0, 64, 8);
  const SignedHeight h(tube.V, tube.F);
  EXPECT_LT(h(Vector3d(0.9, 0, 1)), -0.05);
  EXPECT_GT(h(Vector3d(1.1, 0, 1)), 0.05);
  // Straight above an open end, in line with the wall: beyond the boundary, not under it.
  EXPECT_GE(h(Vector3d(1.0, 0, 2.1)), 0);
}

TEST(SignedHeight, BadMeshThrows) {
  EXPECT_THROW(SignedHeight(MatrixX3d::Zero(3, 3), MatrixX3i(0, 3)), InvalidInput);
  MatrixX3i F(1, 3);
  F << 0, 1, 5;
  EXPECT_THROW(SignedHeight(MatrixX3d::Zero(3, 3), F), InvalidInput);
}

}  // namespace
}  // namespace mq
