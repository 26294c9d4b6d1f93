#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"
#include "core/surface/tangent_field.h"
#include "tests/core/planar_checks.h"
#include "tests/slow/surface_checks.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Issue 4's checks on chain mail over the knight, at a scale where rings are about 4% of the
// bounding-box diagonal: closed manifold elements, no intersections, every vertex inside the
// shell, at least 95% of the surface within 1.5 shell heights of the texture.
TEST(SurfaceQuilting, ChainMailOverTheKnight) {
  const TriMesh base = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  const test::SurfaceRun run = test::run_surface(base, test::tiny_chainmail(), 0.12);
  test::expect_valid_surface_quilt(base, run, 0.95);
  EXPECT_GT(run.stats.iterations, 1);
  // The shell map was built (no fallback) and its optimisation did not increase the stretch.
  EXPECT_TRUE(run.embedding_stats.shell_map_failure.empty())
      << run.embedding_stats.shell_map_failure;
  EXPECT_GT(run.embedding_stats.stretch_before, 1.0);
  EXPECT_LE(run.embedding_stats.stretch_after, run.embedding_stats.stretch_before);
}

TEST(SurfaceQuilting, BaseWithBoundaryAndSeveralComponents) {
  // Two separate open sheets, gently curved: the texture stays over each sheet (its boundary is
  // respected) and both components are covered.
  TriMesh base = test::plane_grid(4, 4, 24, 24);
  for (int v = 0; v < base.num_vertices(); ++v)
    base.V(v, 2) = 0.3 * std::sin(base.V(v, 0)) * std::cos(0.5 * base.V(v, 1));
  TriMesh second = base;
  second.V.col(0).array() += 6.0;
  append_mesh(base, second);
  const test::SurfaceRun run = test::run_surface(base, test::tiny_chainmail(), 0.12, false);
  ASSERT_GT(run.output.num_faces(), 0);
  EXPECT_EQ(intersecting_face_pairs(run.output.V, run.output.F).size(), 0u);
  // Every vertex lies within the shell over the base (never beyond its boundary).
  const Eigen::VectorXd d = point_mesh_distance(run.output.V, base.V, base.F);
  EXPECT_LE(d.maxCoeff(), 1.05 * run.quilt.shell_height + 1e-9);
  // Both components carry texture.
  int on_first = 0, on_second = 0;
  for (int v = 0; v < run.output.num_vertices(); ++v)
    (run.output.V(v, 0) < 5.0 ? on_first : on_second)++;
  EXPECT_GT(on_first, 0);
  EXPECT_GT(on_second, 0);
  EXPECT_GE(surface_coverage(base, run.output, 1.5 * run.quilt.shell_height), 0.8);
}

TEST(SurfaceQuilting, DeterministicAcrossThreadCounts) {
  const TriMesh base = test::torus(2.0, 0.8, 48, 24);
  TriMesh a, b;
  {
    tbb::task_arena one(1);
    one.execute([&] { a = test::run_surface(base, test::tiny_chainmail(), 0.25, false).output; });
  }
  {
    tbb::task_arena two(2);
    two.execute([&] { b = test::run_surface(base, test::tiny_chainmail(), 0.25, false).output; });
  }
  ASSERT_EQ(a.V.rows(), b.V.rows());
  EXPECT_TRUE(a.V == b.V);
  EXPECT_TRUE(a.F == b.F);
}

TEST(SurfaceQuilting, GuidanceFieldOrientsTheSwatch) {
  // With a constant field the quilt differs from the default field's, and it runs.
  const TriMesh base = test::torus(2.0, 0.8, 48, 24);
  const MatrixX3d field = tangent_field_from_direction(base.V, base.F, Vector3d(1, 1, 0));
  const test::SurfaceRun run = test::run_surface(base, test::tiny_chainmail(), 0.25, false, field);
  EXPECT_GT(run.output.num_faces(), 0);
  const test::SurfaceRun plain = test::run_surface(base, test::tiny_chainmail(), 0.25, false);
  EXPECT_FALSE(run.output.V.rows() == plain.output.V.rows() && run.output.V == plain.output.V);
}

}  // namespace
}  // namespace mq
