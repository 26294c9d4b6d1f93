#include <gtest/gtest.h>

#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/outward_orientation.h"
#include "core/mesh/weld_vertices.h"
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

std::vector<int> all_faces(const TriMesh& m) {
  std::vector<int> f(static_cast<size_t>(m.num_faces()));
  for (size_t i = 0; i < f.size(); ++i) f[i] = static_cast<int>(i);
  return f;
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

TEST(OutwardOrientation, OpenSurfacesByTheirWindingNumber) {
  // An open tube facing outward stays; facing inward it turns (rays from its faces escaped
  // through the open ends, so ray parity could not tell).
  TriMesh tube = test::open_cylinder(1.0, 3.0, 48, 12);
  const TriMesh out = tube;
  EXPECT_GT(mean_surface_winding(tube.V, tube.F, all_faces(tube)), 0.1);
  EXPECT_EQ(orient_outward(tube), 0);
  TriMesh in = flipped(tube);
  EXPECT_LT(mean_surface_winding(in.V, in.F, all_faces(in)), -0.1);
  EXPECT_EQ(orient_outward(in), 1);
  EXPECT_TRUE(in.F == out.F);
  // A flat plane either way: no inside, left alone.
  TriMesh plane = test::plane_grid(3, 2, 12, 8), back = flipped(plane);
  EXPECT_NEAR(mean_surface_winding(plane.V, plane.F, all_faces(plane)), 0, 1e-12);
  EXPECT_EQ(orient_outward(plane), 0);
  EXPECT_EQ(orient_outward(back), 0);
}

TEST(OutwardOrientation, TheOpenQuadrupedStaysAndTurnsWhenGivenInsideOut) {
  // Headless Blender's quadruped: legs and tail end in open loops, faces outward.
  const TriMesh quadruped = read_mesh(test::blender_base("quadruped_open.obj"));
  TriMesh as_given = quadruped;
  EXPECT_EQ(orient_outward(as_given), 0);
  EXPECT_TRUE(as_given.F == quadruped.F);
  TriMesh inside_out = flipped(quadruped);
  EXPECT_EQ(orient_outward(inside_out), 1);
  EXPECT_TRUE(inside_out.F == quadruped.F);
  EXPECT_GT(signed_volume(inside_out), 0);
}

}  // namespace
}  // namespace mq
