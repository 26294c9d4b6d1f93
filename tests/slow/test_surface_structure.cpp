// Issue 13 on the shipped meshes, as a user runs them (`meshquilt surface`, method auto: chain
// mail and the weave through the seamless global parameterisation): chain mail keeps its links,
// density and coverage, nothing folded reaches the output, and woven threads run on, breaking
// no more often than on a plane. Figures are printed for the README.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_io.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/swatch_generators.h"
#include "core/shell/quilt_embedding.h"
#include "core/structure/texture_structure.h"
#include "core/surface/global_quilting.h"
#include "host/translation_cost_evaluator.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

struct Result {
  TriMesh output;
  SurfaceQuiltingStats stats;
  QuiltEmbeddingStats embedding;
  StructureSummary structure;
  bool global = false;
};

// The surface command's pipeline with its defaults.
Result quilt_by_default(const TriMesh& base, const TriMesh& swatch, double scale) {
  Result r;
  SurfaceQuiltingOptions o;
  o.scale = scale;
  TranslationCostCpu cost;
  const SurfaceQuilt q =
      quilt_surface_auto(base, swatch, o, cost, &r.stats, nullptr, nullptr, &r.global);
  TetStretchCpu stretch;
  r.output = embed_quilt(q, {}, stretch, &r.embedding);
  r.structure = summarize_structure(r.output, swatch, &base, r.stats.swatch_scale);
  return r;
}

TriMesh mail(int rows, int cols, int detail = 0) {
  ChainMailOptions o;
  o.rows = rows;
  o.cols = cols;
  if (detail) o.ring_segments = detail, o.wire_segments = std::max(4, detail / 4);
  return chainmail_4in1(o);
}

// The figures each job keeps (the honest measure of issue 23: degenerate rings are misses and
// isolated). Issue 13's targets (95%, 90% for the armor) were met under the old measure, which
// counted folded rings as linked; where a job is below them now the README says why.
struct Targets {
  double share = 0.9, isolated = 0.01, density = 0.9, coverage = 0.95;
};

void expect_chain_mail(const char* name, const Result& r, const Targets& t) {
  SCOPED_TRACE(name);
  const StructureReport& s = r.structure.output;
  const StructureComparison& c = r.structure.comparison;
  std::printf(
      "[ measure  ] %s: %d rings, %.2f%% of %d interior rings link 4, %d isolated, "
      "density %.1f%%, coverage %.1f%%, %d folded repaired, %d removed\n",
      name, s.rings, 100 * c.share_matching, s.interior_rings, s.isolated_rings,
      100 * c.density_ratio, 100 * r.embedding.coverage, r.embedding.rigid_repairs,
      r.embedding.removed_intersecting + r.embedding.removed_self_intersecting);
  EXPECT_TRUE(r.global);
  ASSERT_EQ(c.interior_links, 4);
  EXPECT_GE(c.share_matching, t.share);
  EXPECT_LE(s.isolated_rings, t.isolated * s.rings);
  EXPECT_GE(c.density_ratio, t.density);
  EXPECT_GE(r.embedding.coverage, t.coverage);
  EXPECT_TRUE(self_intersecting_components(r.output.V, r.output.F).empty());
  EXPECT_TRUE(intersecting_face_pairs(r.output.V, r.output.F).empty());
}

TEST(SurfaceStructure, SpotDefaultJob) {
  const TriMesh base = read_mesh(std::string(MESHQUILT_SOURCE_DIR) + "/data/spot_6k.obj");
  // 96.7% linked, 96.5% before folded rings were hung over their edge keeping half their links
  // and after the removal too (95.6% before small rings around cones kept the layout's
  // version).
  expect_chain_mail("Spot (default job)", quilt_by_default(base, mail(3, 3, 16), 0.08),
                    {0.94, 0.015});
}

TEST(SurfaceStructure, BunnyAndLink) {
  const TriMesh base = read_mesh(test::shared_data("base/bunny_igl_7k.off"));
  // 96.0% linked, issue 13's 95% (94.3% before folded rings were hung over their edge keeping
  // half their links and after the removal too: 11 folded rings in the output, 2 since; 92.0%
  // before small rings around cones kept the layout's version).
  const Result r = quilt_by_default(base, mail(2, 4), 0.099);
  expect_chain_mail("bunny + link", r, {0.95, 0.03});
  EXPECT_GE(r.embedding.late_unbent_rings, 1);
  EXPECT_LE(r.structure.output.interior_degenerate(), 4);
}

TEST(SurfaceStructure, ChainMailOnTheCup) {
  const TriMesh base = read_mesh(test::shared_data("base/cup_mug_11k.off"));
  // 98.9% linked (97.8% while 14 of its rings were folded over the lip, a sharp crease, counted
  // as misses; they hang over it now).
  expect_chain_mail("cup, chain mail", quilt_by_default(base, mail(5, 6), 0.145), {0.975, 0.0125});
}

// The armor job: at --scale 0.13 a ring (0.042 across) is as wide as the knight's arms are in
// radius, over a 1k-face model with sharp creases and spikes. Measured honestly (issue 23: rings
// folded over the spikes and creases are misses, not links) it is at 86.3% (68% before issue
// 23's layout), short of the 90%: README "Where the targets stand". Its cone metric is
// uneven (mean squared log scale 0.17): the layout follows it partly (scale_exponent 0.73). The
// same knight with rings half the size keeps 94.3%.
TEST(SurfaceStructure, ArmorJobOnTheKnight) {
  const TriMesh base = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  expect_chain_mail("armor (knight)", quilt_by_default(base, mail(5, 6), 0.13), {0.845, 0.06});
  expect_chain_mail("knight, rings half the armor job's", quilt_by_default(base, mail(5, 6), 0.065),
                    {0.925, 0.03});
}

// Rings a tenth of the radius across: the generated cylinder and sphere.
TEST(SurfaceStructure, CylinderAndSphereAtATenthOfTheRadius) {
  const TriMesh ring_sheet = mail(6, 6);
  const double ring = 2.24;  // swatch units
  {
    const TriMesh cylinder = test::open_cylinder(10, 30, 120, 60);
    const double diagonal = bounding_box(cylinder.V, cylinder.F).extent().norm();
    SurfaceQuiltingOptions o;
    const double side = bounding_box(ring_sheet.V).extent().head<2>().maxCoeff();
    Result r = quilt_by_default(cylinder, ring_sheet, 1.0 / ring * side / diagonal);
    Targets t;
    t.share = 0.95;
    expect_chain_mail("cylinder", r, t);
  }
  {
    TriMesh sphere = test::icosphere(5);
    sphere.V *= 10;
    const double diagonal = bounding_box(sphere.V, sphere.F).extent().norm();
    const double side = bounding_box(ring_sheet.V).extent().head<2>().maxCoeff();
    Result r = quilt_by_default(sphere, ring_sheet, 1.0 / ring * side / diagonal);
    Targets t;
    t.share = 0.95;
    t.density = 0.9;
    expect_chain_mail("sphere", r, t);
  }
}

// Woven threads on curved bases run on (issue 23): through the global layout, threads welded
// from one-period pieces end no more often per unit of swatch area than the planar quilt's
// (at most 1.2 times), and the median thread is at least 3 swatch threads long.
TEST(SurfaceStructure, WeaveThreadsOnTheCupAndTheBunny) {
  WeaveOptions w;
  w.threads_x = w.threads_y = 4;
  w.segments_per_cell = 8;
  const TriMesh swatch = plain_weave(w);
  PlanarQuiltingOptions po;
  po.length = po.width = 26;
  TranslationCostCpu cost;
  const TriMesh plane = quilt_plane(swatch, po, cost);
  const StructureReport p = measure_structure(plane);
  ASSERT_GT(p.long_elements, 0);
  const double planar = p.interior_ends_per_area;
  std::printf(
      "[ measure  ] weave on a 26 x 26 plane: %d threads, %.4f interior ends per unit area\n",
      p.long_elements, planar);
  for (const auto& [name, scale] : {std::pair<const char*, double>{"base/cup_mug_11k.off", 0.145},
                                    {"base/bunny_igl_7k.off", 0.1}}) {
    SCOPED_TRACE(name);
    const TriMesh base = read_mesh(test::shared_data(name));
    const Result r = quilt_by_default(base, swatch, scale);
    EXPECT_TRUE(r.global) << "a weave is a lattice of threads: the global layout";
    const StructureReport& s = r.structure.output;
    const StructureComparison& c = r.structure.comparison;
    // Per unit of swatch area: the base's units scaled back by the swatch scale.
    const double per_swatch_area =
        s.interior_ends_per_area * r.stats.swatch_scale * r.stats.swatch_scale;
    std::printf(
        "[ measure  ] weave on %s: %d threads (%d closed), median %.2f swatch threads, %.4f "
        "interior ends per unit of swatch area (planar %.4f), coverage %.1f%%\n",
        name, s.long_elements, s.closed_long_elements, c.long_length_ratio, per_swatch_area, planar,
        100 * r.embedding.coverage);
    EXPECT_GT(s.long_elements, 0);
    EXPECT_LE(per_swatch_area, 1.2 * planar);
    EXPECT_GE(c.long_length_ratio, 3.0);
    EXPECT_GE(r.embedding.coverage, 0.95);
    EXPECT_TRUE(intersecting_face_pairs(r.output.V, r.output.F).empty());
    EXPECT_TRUE(self_intersecting_components(r.output.V, r.output.F).empty());
  }
}

}  // namespace
}  // namespace mq
