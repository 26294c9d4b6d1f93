#include <gtest/gtest.h>

#include <limits>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/longest_edge_bisection.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/weld_vertices.h"
#include "tests/test_support.h"

namespace mq {
namespace {

double longest_edge(const TriMesh& m) {
  double best = 0;
  for (int f = 0; f < m.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      best = std::max(best, (m.V.row(m.F(f, k)) - m.V.row(m.F(f, (k + 1) % 3))).norm());
  return best;
}

TEST(LongestEdgeBisection, BoundsEdgesAndKeepsTheSurface) {
  const TriMesh base = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  const double bound = 0.3 * mean_edge_length(base.V, base.F);
  Refinement r;
  const TriMesh fine = bisect_longest_edges(base, bound, 1 << 22, &r);
  EXPECT_LE(longest_edge(fine), bound);
  EXPECT_GT(fine.num_faces(), 10 * base.num_faces());
  EXPECT_NEAR(surface_area(fine.V, fine.F), surface_area(base.V, base.F),
              1e-9 * surface_area(base.V, base.F));
  const TopologyReport t = topology_report(fine);
  EXPECT_TRUE(t.closed());
  EXPECT_TRUE(t.manifold());
  EXPECT_EQ(t.num_components, topology_report(base).num_components);
  EXPECT_EQ(fine.num_vertices() - edge_topology(fine.F, fine.num_vertices()).num_edges() +
                fine.num_faces(),
            base.num_vertices() - edge_topology(base.F, base.num_vertices()).num_edges() +
                base.num_faces());  // Euler characteristic
  // Faces keep their orientation: normals agree with their parent's.
  const MatrixX3d N = face_normals(fine.V, fine.F), N0 = face_normals(base.V, base.F);
  ASSERT_EQ(r.parent.size(), static_cast<size_t>(fine.num_faces()));
  for (int f = 0; f < fine.num_faces(); ++f)
    EXPECT_GT(N.row(f).dot(N0.row(r.parent[static_cast<size_t>(f)])), 1 - 1e-9) << f;
  // Points map back exactly.
  test::expect_same_points_on_coarse(fine, base, 101,
                                     [&r](int& face, Vector3d& b) { to_parent(r, face, b); });
}

// The reason for bisection over uniform subdivision: small faces next to large ones are left
// alone. On the brick wall (long panels, narrow pillars) uniform 1-to-4 subdivision down to the
// same longest edge makes ~15x more faces.
TEST(LongestEdgeBisection, RefinesOnlyWhereEdgesAreLong) {
  const TriMesh wall = weld_vertices(read_mesh(test::shared_data("base/ivy_brick_wall_84.obj")));
  const double bound = 0.1;
  const TriMesh fine = bisect_longest_edges(wall, bound, 1 << 24);
  EXPECT_LE(longest_edge(fine), bound);
  // 1-to-4 subdivision halves every edge per level and multiplies the face count by 4.
  long long uniform_faces = wall.num_faces();
  for (double e = longest_edge(wall); e > bound;) {
    e *= 0.5;
    uniform_faces *= 4;
  }
  EXPECT_LT(4LL * fine.num_faces(), uniform_faces);
  EXPECT_EQ(topology_report(fine).num_boundary_edges > 0,
            topology_report(wall).num_boundary_edges > 0);
  // Same input, same output.
  const TriMesh again = bisect_longest_edges(wall, bound, 1 << 24);
  EXPECT_EQ(again.V, fine.V);
  EXPECT_EQ(again.F, fine.F);
}

TEST(LongestEdgeBisection, StopsAtTheFaceBudgetAndRejectsBadInput) {
  const TriMesh cube = test::unit_cube();
  const TriMesh capped = bisect_longest_edges(cube, 1e-3, 1000);
  EXPECT_LE(capped.num_faces(), 1000);
  EXPECT_GT(capped.num_faces(), 900);
  EXPECT_TRUE(topology_report(capped).closed());
  const TriMesh same = bisect_longest_edges(cube, 10.0, 1000);
  EXPECT_EQ(same.F, cube.F);
  EXPECT_THROW(bisect_longest_edges(cube, 0.0, 1000), InvalidInput);
  EXPECT_THROW(bisect_longest_edges(cube, std::numeric_limits<double>::quiet_NaN(), 1000),
               InvalidInput);
  TriMesh bad = cube;
  bad.F(0, 1) = 99;
  EXPECT_THROW(bisect_longest_edges(bad, 0.5, 1000), InvalidInput);
}

}  // namespace
}  // namespace mq
