// Issue 25 on real data: the weave over the cup (the global layout's threads, welded of one-period
// pieces) follows a swatch frame that lifts it by a fifth of its thickness. Where the lift would
// fold threads in the cup's concave corners, every thread there fades alike
// (core/shell/swatch_animation, fade_near_meetings): damped one by one, a thread moving less met
// the threads crossing it, and the damping spread until all 59 stood still.
#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_io.h"
#include "core/planar/swatch_generators.h"
#include "core/planar/translation_cost.h"
#include "core/shell/quilt_embedding.h"
#include "core/shell/swatch_animation.h"
#include "core/shell/tet_stretch.h"
#include "core/surface/global_quilting.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(SwatchAnimationCup, ALiftedWeaveFadesOnlyWhereItWouldMeet) {
  WeaveOptions w;
  w.threads_x = w.threads_y = 4;
  w.tube_segments = 8;
  const TriMesh swatch = plain_weave(w);
  SurfaceQuiltingOptions o;
  o.scale = 0.1;
  o.keep_sources = true;
  TranslationCostCpu cpu;
  SurfaceQuiltingStats stats;
  GlobalQuiltingStats g;
  const SurfaceQuilt quilt = quilt_surface_global(
      read_mesh(test::shared_data("base/cup_mug_11k.off")), swatch, o, cpu, &stats, &g);
  ASSERT_TRUE(g.threads);
  QuiltEmbeddingStats e;
  TetStretchCpu stretch;
  const TriMesh rest = embed_quilt(quilt, {}, stretch, &e);
  SwatchAnimation animation(quilt, e.kept, rest, swatch, stats.swatch_scale);
  TriMesh lifted = swatch;
  const double lift =
      0.2 * (swatch.V.col(2).maxCoeff() - swatch.V.col(2).minCoeff()) * stats.swatch_scale;
  lifted.V.col(2).array() += 0.2 * (swatch.V.col(2).maxCoeff() - swatch.V.col(2).minCoeff());
  const std::vector<SwatchMotion> motions{swatch_motion(swatch, lifted, stats.swatch_scale, "f")};
  SettledMotionStats settled;
  animation.settle(motions, &settled);
  const TriMesh moved = animation.frame(motions[0]);
  int full = 0;
  for (int v = 0; v < rest.num_vertices(); ++v)
    full += (moved.V.row(v) - rest.V.row(v)).norm() > 0.99 * lift;
  std::printf(
      "[ measure  ] cup weave lifted by 0.2 of its thickness: %zu threads, %d fade near where "
      "they would meet, %d damped whole, %d still; %.1f%% of vertices move in full\n",
      e.kept.size(), settled.faded, settled.damped, settled.stilled,
      100.0 * full / rest.num_vertices());
  EXPECT_GT(settled.faded, 0);
  EXPECT_EQ(settled.damped + settled.stilled, 0);
  EXPECT_GT(full, 0.9 * rest.num_vertices());
  // Nothing meets that did not at rest, between threads or within one.
  IntersectionOptions all;
  all.between_components_only = false;
  const auto at_rest = intersecting_face_pairs(rest.V, rest.F, all);
  const std::set<std::pair<int, int>> known(at_rest.begin(), at_rest.end());
  for (const auto& pair : intersecting_face_pairs(moved.V, moved.F, all))
    EXPECT_TRUE(known.count(pair)) << pair.first << " " << pair.second;
}

}  // namespace
}  // namespace mq
