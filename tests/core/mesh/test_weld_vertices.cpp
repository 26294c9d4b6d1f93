#include <gtest/gtest.h>

#include <limits>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/longest_edge_bisection.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/weld_vertices.h"
#include "core/surface/local_patch.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// The cube with every face's vertices its own (as exporters write hard-edged boxes).
TriMesh split_cube() {
  const TriMesh cube = test::unit_cube();
  TriMesh split;
  split.V.resize(3 * cube.num_faces(), 3);
  split.F.resize(cube.num_faces(), 3);
  for (int f = 0; f < cube.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      split.V.row(3 * f + k) = cube.V.row(cube.F(f, k));
      split.F(f, k) = 3 * f + k;
    }
  return split;
}

TEST(WeldVertices, ASplitCubeBecomesClosedAgain) {
  const TriMesh split = split_cube();
  ASSERT_EQ(topology_report(split).num_components, 12);
  int merged = -1;
  const TriMesh welded = weld_vertices(split, &merged);
  EXPECT_EQ(welded.num_vertices(), 8);
  EXPECT_EQ(merged, 36 - 8);
  ASSERT_EQ(welded.num_faces(), split.num_faces());
  // Same triangles in the same order.
  for (int f = 0; f < split.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(welded.V.row(welded.F(f, k)), split.V.row(split.F(f, k)));
  EXPECT_TRUE(topology_report(welded).closed());
  EXPECT_EQ(topology_report(welded).num_components, 1);
}

TEST(WeldVertices, LeavesDistinctPositionsAloneAndKeepsOrder) {
  const TriMesh cube = test::unit_cube();
  int merged = -1;
  const TriMesh same = weld_vertices(cube, &merged);
  EXPECT_EQ(merged, 0);
  EXPECT_EQ(same.V, cube.V);
  EXPECT_EQ(same.F, cube.F);
  // Nearly equal is not equal, and -0 equals +0.
  TriMesh t;
  t.V.resize(5, 3);
  t.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1e-12, 0, 0, -0.0, 0, 0;
  t.F.resize(2, 3);
  t.F << 0, 1, 2, 3, 2, 4;
  const TriMesh w = weld_vertices(t, &merged);
  EXPECT_EQ(merged, 1);
  EXPECT_EQ(w.num_vertices(), 4);
  EXPECT_EQ(w.F(1, 2), 0);  // -0 welded onto vertex 0
  EXPECT_EQ(w.F(1, 0), 3);  // 1e-12 kept apart
}

TEST(WeldVertices, RejectsNonFinitePositions) {
  TriMesh t = test::unit_cube();
  t.V(2, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(weld_vertices(t), InvalidInput);
}

// The brick wall of the ivy job is written with split vertices: 146 of them at 56 positions.
// Welded, its boxes are closed and a patch on a pillar (0.5 wide) wraps around the pillar's
// edges instead of being confined to one side, on which no element as long as the swatch fits.
TEST(WeldVertices, PatchesWrapAroundTheBrickWallPillars) {
  const TriMesh wall = read_mesh(test::shared_data("base/ivy_brick_wall_84.obj"));
  int merged = 0;
  const TriMesh welded = weld_vertices(wall, &merged);
  EXPECT_EQ(welded.num_vertices(), 56);
  EXPECT_EQ(merged, wall.num_vertices() - 56);
  const TopologyReport r = topology_report(welded);
  EXPECT_EQ(r.num_non_manifold_edges, 0);
  EXPECT_LT(r.num_boundary_edges, topology_report(wall).num_boundary_edges / 2);

  // Input face 6 is a side of the first pillar (the plane x = 2.54).
  auto widest_turn = [](const TriMesh& base) {
    Refinement r;
    const TriMesh fine = bisect_longest_edges(base, 0.05, 1'000'000, &r);
    // A face of input face 6 near the middle of the pillar's height (y from 0 to 2.7).
    int seed = -1;
    for (int f = 0; f < fine.num_faces() && seed < 0; ++f)
      if (r.parent[static_cast<size_t>(f)] == 6 && std::abs(fine.V(fine.F(f, 0), 1) - 1.35) < 0.1)
        seed = f;
    EXPECT_GE(seed, 0);
    LocalPatchBuilder builder(fine);
    LocalPatchOptions o;
    o.max_area = 3.14159 * 0.6 * 0.6;
    const LocalPatch p = builder.grow(seed, o);
    const MatrixX3d N = face_normals(fine.V, fine.F);
    double turn = 1;
    for (const int f : p.faces) turn = std::min(turn, N.row(f).dot(N.row(seed)));
    return turn;
  };
  EXPECT_GT(widest_turn(wall), 0.99);    // split: stays on the seed's side
  EXPECT_LT(widest_turn(welded), 0.01);  // welded: reaches a side at 90 degrees
}

}  // namespace
}  // namespace mq
