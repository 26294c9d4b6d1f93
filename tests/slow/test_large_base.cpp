// Issue 14: a 1M-face base. The 70k-face Stanford bunny split 1-to-4 twice is the same surface
// in 16 times the faces; quilted with the apples swatch at --scale 0.1 (local patches), the
// finer base is simplified first, so that a patch holds no more faces than on the 70k bunny
// and the result is as valid, as covered and as close to the surface given.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/mesh/closest_point_query.h"
#include "core/mesh/mesh_io.h"
#include "core/planar/swatch_generators.h"
#include "tests/core/shell_fixtures.h"
#include "tests/slow/surface_checks.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(LargeBase, ASplitBunnyCostsPerPatchWhatTheBunnyCosts) {
  const TriMesh bunny = read_mesh(test::shared_data("base/stanford_bunny_70k.obj"));
  const TriMesh fine = test::midpoint_split(test::midpoint_split(bunny));
  ASSERT_GT(fine.num_faces(), 1'000'000);
  const TriMesh apples = apple_layer();
  const test::SurfaceRun coarse_run = test::run_surface(bunny, apples, 0.1);
  const test::SurfaceRun fine_run = test::run_surface(fine, apples, 0.1);
  const auto per_patch = [](const SurfaceQuiltingStats& s) {
    return static_cast<double>(s.patch_faces) / std::max(s.iterations, 1);
  };
  std::printf(
      "[ measure  ] bunny %d faces: %d patches of %.0f faces; split %d faces -> proxy of %d "
      "faces (error %.2e, shell height %.2e): %d patches of %.0f faces; elements %d / %d, "
      "coverage %.3f / %.3f\n",
      bunny.num_faces(), coarse_run.stats.iterations, per_patch(coarse_run.stats), fine.num_faces(),
      fine_run.stats.proxy_faces, fine_run.stats.proxy_error, fine_run.quilt.shell_height,
      fine_run.stats.iterations, per_patch(fine_run.stats), coarse_run.embedding_stats.elements,
      fine_run.embedding_stats.elements, coarse_run.embedding_stats.coverage,
      fine_run.embedding_stats.coverage);
  EXPECT_EQ(coarse_run.stats.proxy_faces, 0) << "70k faces: kept as given";
  EXPECT_GT(fine_run.stats.proxy_faces, 0);
  EXPECT_LT(fine_run.stats.proxy_faces, fine.num_faces() / 10);
  // The shell map is built over the proxy (its faces keep their shape: a shell of this height
  // could not be built over the slivers a simplification without that rule leaves).
  EXPECT_TRUE(fine_run.embedding_stats.shell_map_failure.empty())
      << fine_run.embedding_stats.shell_map_failure;
  EXPECT_LE(fine_run.stats.proxy_error, 0.05 * fine_run.quilt.shell_height);
  // The cost of a patch: its faces, as on the 70k bunny (before: 16 times as many).
  EXPECT_LE(per_patch(fine_run.stats), 1.25 * per_patch(coarse_run.stats));
  // As valid and covered, and as near the surface given (not only the proxy): every vertex
  // within the shell plus the proxy's error of the 1.1M-face base.
  test::expect_valid_surface_quilt(fine_run.quilt.input_base, fine_run, 0.95);
  const double H = fine_run.quilt.shell_height;
  const Eigen::VectorXd d = point_mesh_distance(fine_run.output.V, fine.V, fine.F);
  EXPECT_LE(d.maxCoeff(), 1.05 * H + fine_run.stats.proxy_error);
  EXPECT_GE(fine_run.embedding_stats.elements, 0.9 * coarse_run.embedding_stats.elements);
}

}  // namespace
}  // namespace mq
