#include <gtest/gtest.h>

#include "core/mesh/mesh_topology.h"
#include "core/shell/quilt_embedding.h"
#include "core/shell/signed_height.h"
#include "core/shell/surface_coverage.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// A tetrahedron over base face f: three corners at height 0.2 H around the face's centroid,
// the apex over it at 0.8 H.
SurfaceElement tetrahedron_over(int f, double H) {
  SurfaceElement e;
  e.face.assign(4, f);
  e.barycentric.resize(4, 3);
  e.barycentric << 0.5, 0.25, 0.25, 0.25, 0.5, 0.25, 0.25, 0.25, 0.5, 1.0 / 3, 1.0 / 3, 1.0 / 3;
  e.height.resize(4);
  e.height << 0.2 * H, 0.2 * H, 0.2 * H, 0.8 * H;
  e.F.resize(4, 3);
  e.F << 0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3;
  return e;
}

// Two unit cubes 0.01 apart (each face split in 16), one tetrahedron over each of their 384
// faces, shell height 0.1: those over the facing sides reach 0.02 to 0.08 out, into the other
// cube.
SurfaceQuilt two_cubes_a_hair_apart() {
  SurfaceQuilt q;
  q.shell_height = 0.1;
  q.input_base = test::midpoint_split(test::midpoint_split(test::unit_cube()));
  TriMesh other = q.input_base;
  other.V.col(0).array() += 1.01;
  append_mesh(q.input_base, other);
  q.base = q.input_base;
  for (int f = 0; f < q.base.num_faces(); ++f) q.elements.push_back(tetrahedron_over(f, 0.1));
  return q;
}

bool over_a_facing_side(const TriMesh& base, int f) {
  double x = 0;
  for (int k = 0; k < 3; ++k) x += base.V(base.F(f, k), 0) / 3;
  return std::abs(x - 1) < 1e-9 || std::abs(x - 1.01) < 1e-9;
}

TEST(QuiltEmbedding, TextureInsideTheBaseIsRemovedAndCounted) {
  const SurfaceQuilt q = two_cubes_a_hair_apart();
  int facing = 0;
  for (int f = 0; f < q.base.num_faces(); ++f) facing += over_a_facing_side(q.base, f);
  ASSERT_EQ(facing, 64);
  for (const bool shell : {true, false}) {
    QuiltEmbeddingOptions o;
    o.shell_map = shell;
    TetStretchCpu cpu;
    QuiltEmbeddingStats stats;
    const TriMesh out = embed_quilt(q, o, cpu, &stats);
    // The shell map is built without the facing sides (its shells clash there), which are
    // placed by normal displacement; through either, the tetrahedra there end inside the other
    // cube: found, and removed.
    if (shell) {
      EXPECT_TRUE(stats.shell_map_failure.empty()) << stats.shell_map_failure;
      EXPECT_GT(stats.fallback_faces, 0);
      EXPECT_GE(stats.fallback_elements, 64);
      EXPECT_GT(stats.fallback_area_share, 0);
      EXPECT_LT(stats.fallback_area_share, 0.5);
    } else {
      EXPECT_EQ(stats.fallback_area_share, 0);
    }
    // The facing sides' tetrahedra: a sixth of the vertices (a few tips by the cubes' edges,
    // lifted along the shell's smoothed directions, clear the other cube).
    EXPECT_NEAR(stats.below_base_embedded, 1.0 / 6, 0.01) << shell;
    EXPECT_EQ(stats.removed_below, 64) << shell;
    EXPECT_EQ(stats.elements, 320) << shell;
    EXPECT_EQ(stats.below_base, 0);
    EXPECT_EQ(stats.checked_vertices, 1280);
    EXPECT_GE(stats.lowest_height, -0.01);
    // Checked independently: no output vertex more than 1% of H inside the base.
    const SignedHeight h(q.input_base.V, q.input_base.F);
    for (int v = 0; v < out.num_vertices(); ++v)
      EXPECT_GE(h(Vector3d(out.V.row(v).transpose())), -0.001) << v;
    // Coverage counts what is outside: the facing sides are bare but for their borders.
    EXPECT_LT(stats.coverage, 0.95) << shell;
    EXPECT_GT(stats.coverage, 320.0 / 384) << shell;
    EXPECT_EQ(stats.coverage, surface_coverage(q.base, out, 0.15, 0.001));
  }
}

}  // namespace
}  // namespace mq
