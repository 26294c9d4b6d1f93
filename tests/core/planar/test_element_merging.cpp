// Element merging (paper section 2.7): the coincidence rule and cut-and-stitch of two related
// elements into one.
#include <gtest/gtest.h>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/element_merging.h"
#include "core/planar/synthesis_grid.h"
#include "tests/core/planar/cut_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

Element element_of(const TriMesh& m) {
  Element e;
  e.V = m.V;
  e.F = m.F;
  e.update();
  return e;
}

TEST(ElementMerging, ElementsCoincide) {
  const Element a = element_of(test::torus(1.0, 0.3, 24, 12));
  const double tol = 0.05;
  EXPECT_TRUE(elements_coincide(a, a, tol));
  Element near = a;
  near.translate(Vector3d(0, 0, 0.5 * tol));
  EXPECT_TRUE(elements_coincide(a, near, tol));
  // Bounding boxes shifted by nearly the tolerance sideways: still within it.
  Element beside = a;
  beside.translate(Vector3d(0.9 * tol, 0, 0));
  EXPECT_TRUE(elements_coincide(a, beside, tol));
  EXPECT_TRUE(elements_coincide(beside, a, tol));
  Element far = a;
  far.translate(Vector3d(0, 0, 2 * tol));
  EXPECT_FALSE(elements_coincide(a, far, tol));
  // Half of the element lies on the whole one, but not the other way round.
  std::vector<int> half;
  for (int f = 0; f < a.F.rows(); ++f)
    if (a.V(a.F(f, 0), 0) > 0 && a.V(a.F(f, 1), 0) > 0 && a.V(a.F(f, 2), 0) > 0) half.push_back(f);
  const Element h = element_of(extract_faces(a.mesh(), half));
  EXPECT_FALSE(elements_coincide(a, h, tol));
  EXPECT_FALSE(elements_coincide(h, a, tol));
}

// An output tube over x in [0, 6] and a swatch tube over [4, 10] on the same axis (another
// tessellation phase), the overlap region being x in [4, 6]: cells left of x = 6 processed,
// the patch starting at x = 4.
struct OverlappingTubes {
  SynthesisGrid grid{Vector2d(-1, -3), 0.5, 24, 12};
  Element out, in;
  double mean_edge = 0;
  OverlappingTubes() {
    for (int i = 0; i < grid.num_cells(); ++i)
      if (grid.cell(i).x < 14) grid.set_processed(grid.cell(i));  // x < 6
    out = element_of(test::tube(0, 6, 30, 12, 0.4, 0.0, true));
    in = element_of(test::tube(4, 10, 30, 12, 0.4, 0.13, true));
    mean_edge = mean_edge_length(out.V, out.F);
  }
};

TEST(ElementMerging, CutAndStitchJoinsTwoOverlappingCappedTubes) {
  OverlappingTubes fx;
  const OverlapRegion region(Vector2d(4, -2), Vector2d(10, 2), fx.grid.processed_snapshot());
  StitchFailure why = StitchFailure::BadSeam;
  const std::optional<Element> joined =
      cut_and_stitch(fx.out, fx.in, region, fx.mean_edge, MergeOptions{}, &why);
  ASSERT_TRUE(joined.has_value()) << "refused: " << stitch_failure_name(why);
  EXPECT_EQ(why, StitchFailure::None);
  const TriMesh m = joined->mesh();
  const TopologyReport r = topology_report(m);
  EXPECT_EQ(r.num_components, 1);
  EXPECT_TRUE(r.closed());
  EXPECT_TRUE(r.manifold());
  EXPECT_EQ(r.num_degenerate_faces, 0);
  IntersectionOptions all_pairs;
  all_pairs.between_components_only = false;
  EXPECT_TRUE(intersecting_face_pairs(m.V, m.F, all_pairs).empty());
  // The union of both: from the output's far cap to the swatch's, one tube (no doubled wall:
  // its area is about that of a single 10-long tube, well below the two inputs together).
  EXPECT_NEAR(joined->lo.x(), 0.0, 1e-9);
  EXPECT_NEAR(joined->hi.x(), 10.0, 1e-9);
  const double single = surface_area(fx.out.V, fx.out.F) * 10.0 / 6.0;
  const double area = surface_area(m.V, m.F);
  EXPECT_GT(area, 0.85 * single);
  EXPECT_LT(area, 1.15 * single);
  // The kept parts stay where they were: the far ends are the inputs' own vertices.
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double radial = std::hypot(m.V(v, 1), m.V(v, 2));
    EXPECT_LT(radial, 0.4 + 2 * fx.mean_edge) << "vertex " << v;
  }
}

TEST(ElementMerging, CutAndStitchRefusesUnrelatedElements) {
  OverlappingTubes fx;
  // The swatch tube moved sideways, out of reach of the output's: nothing to join.
  Element far = fx.in;
  far.translate(Vector3d(0, 0, 3.0));
  const OverlapRegion region(Vector2d(4, -2), Vector2d(10, 2), fx.grid.processed_snapshot());
  StitchFailure why = StitchFailure::None;
  EXPECT_FALSE(cut_and_stitch(fx.out, far, region, fx.mean_edge, MergeOptions{}, &why));
  EXPECT_NE(why, StitchFailure::None);
}

}  // namespace
}  // namespace mq
