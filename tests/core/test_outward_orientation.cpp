#include <gtest/gtest.h>

#include "core/mesh_io.h"
#include "core/mesh_topology.h"
#include "core/outward_orientation.h"
#include "core/weld_vertices.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Signed volume about the origin (exact for closed surfaces and for open boxes standing on the
// plane through the origin, whose missing faces add nothing).
double signed_volume(const TriMesh& m) {
  double v = 0;
  for (int f = 0; f < m.num_faces(); ++f) {
    const Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    v += a.dot(b.cross(c)) / 6;
  }
  return v;
}

TriMesh flipped(TriMesh m) {
  for (int f = 0; f < m.num_faces(); ++f) std::swap(m.F(f, 1), m.F(f, 2));
  return m;
}

TEST(OutwardOrientation, InsideOutSurfacesTurnAndOutwardOnesStay) {
  TriMesh torus = test::torus(1.0, 0.3, 32, 12);
  TriMesh cube = test::unit_cube();
  EXPECT_EQ(orient_outward(torus), 0);
  EXPECT_EQ(orient_outward(cube), 0);
  TriMesh in_torus = flipped(torus), in_cube = flipped(cube);
  EXPECT_EQ(orient_outward(in_torus), 1);
  EXPECT_EQ(orient_outward(in_cube), 1);
  EXPECT_TRUE(in_torus.F == torus.F);
  EXPECT_TRUE(in_cube.F == cube.F);
  // An open sheet has no inside: either orientation stays.
  TriMesh sheet = test::plane_grid(2, 1, 8, 4), back = flipped(sheet);
  EXPECT_EQ(orient_outward(sheet), 0);
  EXPECT_EQ(orient_outward(back), 0);
  // Several components: only the inside-out one turns.
  TriMesh both = torus;
  TriMesh moved = flipped(cube);
  moved.V.col(0).array() += 5;
  append_mesh(both, moved);
  EXPECT_EQ(orient_outward(both), 1);
  EXPECT_GT(signed_volume(both), 0);
}

TEST(OutwardOrientation, TheIvyWallsBoxesFaceOutwardAfterwards) {
  // ../shared/data's brick wall: boxes open at the bottom (y = 0), written inside out, with
  // their sides' vertices split (welded first, as the surface pipeline does).
  TriMesh wall = weld_vertices(read_mesh(test::shared_data("base/ivy_brick_wall_84.obj")));
  ASSERT_LT(signed_volume(wall), 0);
  EXPECT_GT(orient_outward(wall), 0);
  EXPECT_GT(signed_volume(wall), 0);
  // Every box on its own: a positive volume.
  std::vector<int> fc;
  const int n = connected_components(wall.F, wall.num_vertices(), fc);
  const auto groups = component_faces(fc, n);
  int outward = 0;
  for (const auto& g : groups) outward += signed_volume(extract_faces(wall, g)) > 0;
  EXPECT_EQ(outward, n);
}

}  // namespace
}  // namespace mq
