#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "core/structure/texture_structure.h"
#include "tests/core/ring_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TriMesh moved(TriMesh m, const Eigen::Matrix3d& R, const Vector3d& t) {
  for (int v = 0; v < m.num_vertices(); ++v) m.V.row(v) = (R * m.V.row(v).transpose() + t);
  return m;
}

// A sheet's options (ChainMailOptions or SquareMailOptions) at few segments (fast to measure),
// rows x cols.
template <class Options>
Options small_sheet(int rows, int cols) {
  Options o;
  o.rows = rows;
  o.cols = cols;
  o.ring_segments = 16;
  o.wire_segments = 4;
  return o;
}
SquareMailOptions small_square(int rows, int cols) {
  return small_sheet<SquareMailOptions>(rows, cols);
}
ChainMailOptions small_4in1(int rows, int cols) {
  return small_sheet<ChainMailOptions>(rows, cols);
}

// A chain of n tori (radius 1, wire 0.15) along x, alternately in the xy and xz planes, each
// threaded through the next.
TriMesh chain(int n) {
  const TriMesh ring = test::torus(1.0, 0.15, 32, 8);
  const Eigen::Matrix3d flip = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()).toRotationMatrix();
  TriMesh out;
  for (int i = 0; i < n; ++i) {
    const TriMesh r =
        moved(ring, i % 2 ? flip : Eigen::Matrix3d::Identity(), Vector3d(1.6 * i, 0, 0));
    if (out.empty())
      out = r;
    else
      append_mesh(out, r);
  }
  return out;
}

TEST(TextureStructure, ChainLinksEachRingToItsNeighbours) {
  const StructureReport r = measure_structure(chain(5));
  ASSERT_EQ(r.rings, 5);
  EXPECT_EQ(r.linked_pairs.size(), 4u);
  EXPECT_EQ(r.elements[0].links, 1);
  for (int i = 1; i < 4; ++i) EXPECT_EQ(r.elements[i].links, 2) << i;
  EXPECT_EQ(r.elements[4].links, 1);
  EXPECT_EQ(r.isolated_rings, 0);
  EXPECT_EQ(r.long_elements, 0);
}

TEST(TextureStructure, SameRingsSideBySideAreNotLinked) {
  // The chain's rings all in one plane, overlapping boxes but threaded through nothing.
  const TriMesh ring = test::torus(1.0, 0.15, 32, 8);
  TriMesh row = ring;
  for (int i = 1; i < 4; ++i)
    append_mesh(row,
                moved(ring, Eigen::Matrix3d::Identity(), Vector3d(2.4 * i, 0.0, 0.4 * (i % 2))));
  const StructureReport r = measure_structure(row);
  EXPECT_EQ(r.rings, 4);
  EXPECT_TRUE(r.linked_pairs.empty());
  EXPECT_EQ(r.isolated_rings, 4);
  // And the chain with one ring pulled out of its neighbour is broken there.
  TriMesh broken = chain(4);
  for (int v = broken.num_vertices() / 2; v < broken.num_vertices(); ++v) broken.V(v, 0) += 1.5;
  const StructureReport b = measure_structure(broken);
  EXPECT_EQ(b.linked_pairs.size(), 2u);
}

TEST(TextureStructure, FourInOneSheetHasFourLinksInsideAndItsLatticeDensity) {
  ChainMailOptions o;
  o.rows = 6;
  o.cols = 6;
  const SwatchStructure s = measure_swatch_structure(chainmail_4in1(o));
  EXPECT_EQ(s.report.rings, 36);
  EXPECT_EQ(s.interior_links, 4);
  EXPECT_EQ(s.report.linked_pairs.size(), 55u);
  // Interior rings (a ring size and a spacing inside the sheet's box) all have 4 links.
  o.rows = o.cols = 10;
  const StructureReport big = measure_structure(chainmail_4in1(o));
  ASSERT_GE(big.interior_rings, 16);
  EXPECT_EQ(big.share_with_links(4), 1.0);
  // One ring per 1.25 R x 1.25 R lattice cell.
  EXPECT_NEAR(s.density, 1.0 / (1.25 * 1.25), 1e-9);
  // A sheet two rings high has no closed Voronoi cell: the lattice cell gives the same.
  o.rows = 2;
  o.cols = 4;
  const SwatchStructure narrow = measure_swatch_structure(chainmail_4in1(o));
  EXPECT_EQ(narrow.interior_links, 4);
  EXPECT_NEAR(narrow.density, 1.0 / (1.25 * 1.25), 1e-9);
  // Scaled and turned on its side, the swatch measures the same.
  const TriMesh turned = moved(
      chainmail_4in1(o), 2.0 * Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitY()).toRotationMatrix(),
      Vector3d(1, 2, 3));
  const SwatchStructure t = measure_swatch_structure(turned);
  EXPECT_EQ(t.interior_links, 4);
  EXPECT_NEAR(t.density, 1.0 / (2.5 * 2.5), 1e-9);
}

TEST(TextureStructure, RingsMissingFromASheetLowerTheShareAndTheDensity) {
  ChainMailOptions o;
  o.rows = 10;
  o.cols = 10;
  const TriMesh sheet = chainmail_4in1(o);
  std::vector<int> fc;
  const int n = connected_components(sheet.F, sheet.num_vertices(), fc);
  const auto groups = component_faces(fc, n);
  // Drop every fifth ring.
  std::vector<int> keep;
  for (int c = 0; c < n; ++c)
    if (c % 5 != 2) keep.insert(keep.end(), groups[c].begin(), groups[c].end());
  const TriMesh holes = extract_faces(sheet, keep);
  const SwatchStructure s = measure_swatch_structure(sheet);
  const StructureReport full = measure_structure(sheet), r = measure_structure(holes);
  const StructureComparison cf = compare_structure(full, s), ch = compare_structure(r, s);
  EXPECT_EQ(cf.share_matching, 1.0);
  EXPECT_LT(ch.share_matching, 0.8);  // rows 2 and 7 of every column are gone
  EXPECT_NEAR(ch.density_ratio / cf.density_ratio, 0.8, 0.03);
  EXPECT_NEAR(ch.linear_scale, 1.0, 1e-9);
}

// The same mesh with its faces in another order: its vertices, numbered by first use, no longer
// follow any swatch element's.
TriMesh reordered(const TriMesh& m) {
  const int n = m.num_faces();
  TriMesh out = m;
  for (int f = 0; f < n; ++f) out.F.row((f * 7 + 3) % n) = m.F.row(f);  // n is even, 7 odd
  return out;
}

// Shapes are judged against the swatch element at the output's scale: a sheet turned, moved and
// scaled by 3 is all copies of size 1 and aspect 1; one ring stretched 2x along x has size
// sqrt(2), aspect 2 and stretch 2, by its vertex correspondence and, renumbered, by its principal
// extents; a ring shrunk to 0.8 has size 0.8 and aspect 1.
TEST(TextureStructure, ShapeFiguresAgainstTheSwatchElementAtTheOutputScale) {
  ChainMailOptions o;
  o.rows = 6;
  o.cols = 6;
  const TriMesh sheet = chainmail_4in1(o);
  const SwatchStructure s = measure_swatch_structure(sheet);
  ASSERT_EQ(s.kinds.size(), 1u);
  EXPECT_EQ(s.kinds[0].shapes.size(), 1u) << "the sheet's rings are one shape up to rotation";
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const TriMesh out = moved(sheet, 3.0 * R, Vector3d(5, -2, 1));
  StructureOptions so;
  so.swatch = &s;
  so.linear_scale = 3.0;
  const StructureComparison plain = compare_structure(measure_structure(out, so), s);
  EXPECT_EQ(plain.shape.elements, 36);
  EXPECT_EQ(plain.shape.by_correspondence, 36);
  EXPECT_NEAR(plain.shape.size_median, 1.0, 1e-9);
  EXPECT_NEAR(plain.shape.size_max, 1.0, 1e-9);
  EXPECT_NEAR(plain.shape.aspect_max, 1.0, 1e-9);
  EXPECT_EQ(plain.stretched, 0);
  EXPECT_NEAR(plain.largest_stretch, 1.0, 1e-9);
  EXPECT_NEAR(plain.linear_scale, 3.0, 1e-12);

  std::vector<int> fc;
  const int n = connected_components(sheet.F, sheet.num_vertices(), fc);
  const auto groups = component_faces(fc, n);
  const auto with_ring = [&](const std::function<TriMesh(TriMesh)>& change) {
    TriMesh ring = change(extract_faces(sheet, groups[14]));
    std::vector<int> others;
    for (int c = 0; c < n; ++c)
      if (c != 14) others.insert(others.end(), groups[c].begin(), groups[c].end());
    TriMesh m = extract_faces(sheet, others);
    append_mesh(m, ring);
    set_single_kind(m, "ring");
    return moved(m, 3.0 * Eigen::Matrix3d::Identity(), Vector3d::Zero());
  };
  const auto stretch_x = [](TriMesh ring) {
    const double cx = ring.V.col(0).mean();
    ring.V.col(0) = ((ring.V.col(0).array() - cx) * 2.0 + cx).matrix();
    return ring;
  };
  for (const bool copy : {true, false}) {
    SCOPED_TRACE(copy ? "by correspondence" : "by principal extents");
    const StructureReport r =
        measure_structure(with_ring([&](const TriMesh& ring) {
                            return copy ? stretch_x(ring) : reordered(stretch_x(ring));
                          }),
                          so);
    const ElementStructure& e = r.elements.back();
    EXPECT_EQ(e.by_correspondence, copy);
    EXPECT_NEAR(e.size_ratio, std::sqrt(2.0), copy ? 1e-9 : 0.02);
    EXPECT_NEAR(e.aspect, 2.0, copy ? 1e-9 : 0.04);
    EXPECT_NEAR(e.stretch, 2.0, copy ? 1e-9 : 0.04);
    const StructureComparison c = compare_structure(r, s);
    EXPECT_EQ(c.stretched, 1);
    EXPECT_NEAR(c.largest_stretch, 2.0, copy ? 1e-9 : 0.04);
    EXPECT_NEAR(c.shape.size_max, std::sqrt(2.0), copy ? 1e-9 : 0.02);
    EXPECT_NEAR(c.shape.size_median, 1.0, 1e-9);
    EXPECT_NEAR(c.shape.aspect_median, 1.0, 1e-9);
  }
  const StructureReport small = measure_structure(
      with_ring([](TriMesh ring) {
        const Vector3d c = ring.V.colwise().mean().transpose();
        ring.V = ((ring.V.rowwise() - c.transpose()) * 0.8).rowwise() + c.transpose();
        return ring;
      }),
      so);
  EXPECT_NEAR(small.elements.back().size_ratio, 0.8, 1e-9);
  EXPECT_NEAR(small.elements.back().aspect, 1.0, 1e-9);
  EXPECT_NEAR(compare_structure(small, s).shape.size_p99, 1.0, 1e-9) << "one of 36: under the 99th";
  // Without the scale it is estimated from the median areas: the copies still measure 1.
  so.linear_scale = 0;
  EXPECT_NEAR(compare_structure(measure_structure(out, so), s).shape.size_median, 1.0, 1e-6);
  // Threads are not compact elements: a weave has no shape figures.
  const TriMesh weave = plain_weave();
  const SwatchStructure ws = measure_swatch_structure(weave);
  StructureOptions wo;
  wo.swatch = &ws;
  const StructureComparison w = compare_structure(measure_structure(weave, wo), ws, 1.0);
  EXPECT_EQ(w.shape.elements, 0);
  EXPECT_EQ(w.stretched, 0);
}

// Ring T (flat, xy plane, at the origin) between two rings in the xz plane threaded through its
// hole at x = +-0.6 (a piece of chain), with T changed by `shape` (T's own coordinates).
TriMesh chain_through(const TriMesh& t) {
  const TriMesh ring = test::torus(1.0, 0.15, 48, 12);
  const Eigen::Matrix3d up = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()).toRotationMatrix();
  TriMesh out = moved(ring, up, Vector3d(-1.6, 0, 0));
  append_mesh(out, t);
  append_mesh(out, moved(ring, up, Vector3d(1.6, 0, 0)));
  return out;
}

// The same map with x and y exchanged: bends along x (through the partners' crossings) rather
// than across.
std::function<Vector3d(const Vector3d&)> along_x(
    const std::function<Vector3d(const Vector3d&)>& f) {
  return [f](const Vector3d& p) {
    const Vector3d q = f(Vector3d(p.y(), p.x(), p.z()));
    return Vector3d(q.y(), q.x(), q.z());
  };
}

// Issue 23: a ring squeezed until its hole closes, or folded over an edge into a C, keeps a centre
// loop its partners' loops pass through, but it is degenerate: a miss, linking nothing, so its
// partners lose that link. Mildly squeezed, or bent gently over a cylinder, it stays linked.
TEST(TextureStructure, DegenerateRingsAreMissesAndLinkNothing) {
  const TriMesh torus = test::torus(1.0, 0.15, 48, 12);
  struct Case {
    const char* name;
    TriMesh ring;
    RingDefect defect;
  };
  const std::vector<Case> cases = {
      {"flat", torus, RingDefect::None},
      {"squeezed mildly (ellipse 1 x 0.6)", test::ellipse_ring(0.6, 0.15), RingDefect::None},
      {"squeezed shut (sides 0.32 apart)", test::stadium_ring(0.16, 0.15), RingDefect::NoHole},
      {"bent over a cylinder of 10 radii",
       test::mapped(torus, along_x([](const Vector3d& p) { return test::over_cylinder(p, 10); })),
       RingDefect::None},
      {"bent over a right-angled edge into a C",
       test::mapped(torus, along_x([](const Vector3d& p) { return test::over_edge(p, 0.2); })),
       RingDefect::Folded},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    StructureOptions so;
    so.interior_margin = 1e-9;  // a closed piece of chain: every ring judged
    so.automatic_border = false;
    const StructureReport r = measure_structure(chain_through(c.ring), so);
    ASSERT_EQ(r.rings, 3);
    const ElementStructure& t = r.elements[1];
    EXPECT_EQ(t.defect, c.defect);
    EXPECT_EQ(t.loop_links, 2) << "its centre loop is threaded by both partners";
    EXPECT_EQ(r.loop_linked_pairs, 2);
    const bool degenerate = c.defect != RingDefect::None;
    EXPECT_EQ(t.links, degenerate ? 0 : 2);
    EXPECT_EQ(r.elements[0].links, degenerate ? 0 : 1);
    EXPECT_EQ(r.elements[2].links, degenerate ? 0 : 1);
    EXPECT_EQ(r.linked_pairs.size(), degenerate ? 0u : 2u);
    EXPECT_EQ(r.isolated_rings, degenerate ? 3 : 0);
    EXPECT_EQ(r.degenerate_rings(), degenerate ? 1 : 0);
    EXPECT_EQ(r.defects[static_cast<size_t>(c.defect)], degenerate ? 1 : 3);
    // Histograms hold the rings that are not degenerate; the share counts degenerate as misses.
    int counted = 0;
    for (const int h : r.interior_link_histogram) counted += h;
    EXPECT_EQ(counted + r.interior_degenerate(), r.interior_rings);
    EXPECT_NEAR(r.share_with_links(2), degenerate ? 0.0 : 1.0 / 3, 1e-12);
  }
}

// A ring of a ring kind that is not ring-shaped (torn open) is a degenerate ring, not a thread:
// its partners lose their link to it, and the kind says so whether the mesh names kinds or not.
TEST(TextureStructure, TornRingOfARingKindIsADegenerateRing) {
  ChainMailOptions o;
  o.rows = o.cols = 6;
  o.ring_segments = 16;
  o.wire_segments = 4;
  const TriMesh sheet = chainmail_4in1(o);
  std::vector<int> fc;
  const int n = connected_components(sheet.F, sheet.num_vertices(), fc);
  const auto groups = component_faces(fc, n);
  std::vector<int> keep;
  for (int c = 0; c < n; ++c)
    for (size_t k = 0; k < groups[c].size(); ++k)
      if (c != 14 || k % 8 != 0)
        keep.push_back(groups[c][k]);  // ring 14 loses an eighth of its faces
  TriMesh torn = extract_faces(sheet, keep);
  const StructureReport full = measure_structure(sheet);
  for (const bool named : {true, false}) {
    SCOPED_TRACE(named ? "kinds named" : "no kinds");
    if (!named) {
      torn.kinds.clear();
      torn.face_kind.clear();
    }
    const StructureReport r = measure_structure(torn);
    std::vector<int> tc;
    connected_components(torn.F, torn.num_vertices(), tc);
    int element = -1;
    for (size_t f = 0; f < keep.size(); ++f)
      if (fc[keep[f]] == 14) element = tc[f];
    ASSERT_GE(element, 0);
    const ElementStructure& e = r.elements[static_cast<size_t>(element)];
    EXPECT_TRUE(e.ring);
    EXPECT_FALSE(e.ring_shaped);
    EXPECT_FALSE(e.long_element);
    EXPECT_EQ(e.defect, RingDefect::NotRing);
    EXPECT_EQ(r.rings, 36);
    EXPECT_EQ(r.long_elements, 0);
    EXPECT_EQ(r.defects[static_cast<size_t>(RingDefect::NotRing)], 1);
    // Its partners each lost that one link.
    EXPECT_EQ(static_cast<int>(r.linked_pairs.size()),
              static_cast<int>(full.linked_pairs.size()) - full.elements[14].links);
  }
}

// The square 4-in-1 sheet: flat rings hold 4 connectors, connectors 2 flat rings. Judged per
// kind it keeps all of its structure against itself; a single count (4) would call every
// connector a miss. An output without kind names is matched by its elements' shapes.
TEST(TextureStructure, TwoRingKindsAreJudgedEachByItsOwnCount) {
  SquareMailOptions o;
  o.rows = o.cols = 7;
  o.ring_segments = 24;
  o.wire_segments = 6;
  const TriMesh sheet = chainmail_square(o);
  const SwatchStructure s = measure_swatch_structure(sheet);
  ASSERT_EQ(s.kinds.size(), 2u);
  EXPECT_EQ(s.kinds[0].name, "ring");
  EXPECT_EQ(s.kinds[1].name, "connector");
  EXPECT_TRUE(s.kinds[0].ring && s.kinds[1].ring);
  EXPECT_EQ(s.kinds[0].interior_links, 4);
  EXPECT_EQ(s.kinds[1].interior_links, 2);
  EXPECT_EQ(s.ring_kinds(), 2);
  for (const bool named : {true, false}) {
    SCOPED_TRACE(named ? "kinds named" : "no kinds");
    TriMesh out = moved(sheet, 2.0 * Eigen::Matrix3d::Identity(), Vector3d(3, 1, 0));
    if (!named) {
      out.kinds.clear();
      out.face_kind.clear();
    }
    StructureOptions so;
    so.swatch = &s;
    const StructureReport r = measure_structure(out, so);
    const StructureComparison c = compare_structure(r, s);
    ASSERT_GT(r.interior_rings, 10);
    EXPECT_EQ(c.share_matching, 1.0);
    ASSERT_EQ(c.kinds.size(), 2u);
    EXPECT_EQ(c.kinds[0].kind, "ring");
    EXPECT_EQ(c.kinds[0].interior_links, 4);
    EXPECT_EQ(c.kinds[0].share, 1.0);
    EXPECT_EQ(c.kinds[1].kind, "connector");
    EXPECT_EQ(c.kinds[1].interior_links, 2);
    EXPECT_EQ(c.kinds[1].share, 1.0);
    EXPECT_EQ(c.kinds[0].interior_rings + c.kinds[1].interior_rings, r.interior_rings);
    // Against the one count of 4 only the flat rings would match.
    EXPECT_EQ(r.share_with_links(4),
              static_cast<double>(c.kinds[0].interior_rings) / r.interior_rings);
    EXPECT_NEAR(c.shape.size_max, 1.0, 1e-9);
  }
}

// A sheet two rings wide has no ring with all its links (the square pattern's flat rings show 3
// of their 4, the 4-in-1 sheet of one row 2); its translates together show them all, as in the
// sheet it repeats. A sheet whose rings are no translates of each other is judged by its own.
TEST(TextureStructure, ASheetTwoRingsWideIsJudgedAsTheSheetItRepeats) {
  for (const auto& [rows, cols] : {std::pair{2, 5}, std::pair{5, 2}, std::pair{2, 2}}) {
    SCOPED_TRACE(testing::Message() << rows << " x " << cols);
    const SwatchStructure s = measure_swatch_structure(chainmail_square(small_square(rows, cols)));
    ASSERT_EQ(s.kinds.size(), 2u);
    EXPECT_EQ(s.kinds[0].interior_links, 4);
    EXPECT_EQ(s.kinds[1].interior_links, 2);
  }
  EXPECT_EQ(measure_swatch_structure(chainmail_4in1(small_4in1(2, 4))).kinds[0].interior_links, 4);
  // One ring moved by its own amount breaks its class: the rest still judge 4.
  TriMesh sheet = chainmail_4in1(small_4in1(4, 4));
  std::vector<int> fc;
  connected_components(sheet.F, sheet.num_vertices(), fc);
  std::vector<char> moved_vertex(static_cast<size_t>(sheet.num_vertices()), 0);
  for (int f = 0; f < sheet.F.rows(); ++f)
    if (fc[static_cast<size_t>(f)] == 0)
      for (int k = 0; k < 3; ++k) moved_vertex[static_cast<size_t>(sheet.F(f, k))] = 1;
  for (int v = 0; v < sheet.num_vertices(); ++v)
    if (moved_vertex[static_cast<size_t>(v)]) sheet.V(v, 2) += 1e-3 * sheet.V(v, 0);
  EXPECT_EQ(measure_swatch_structure(sheet).kinds[0].interior_links, 4);
}

// A swatch of copies has the density of the sheet it repeats, whatever its size: the square
// pattern one flat ring and two connectors per period squared (by Voronoi cells the 2 x 5 sheet
// measured 11% under it, the 6 x 6 one 1.8%), the 4-in-1 sheets one value for every size.
// Elements that are no copies (apples) keep the Voronoi figure.
TEST(TextureStructure, ASwatchOfCopiesHasTheDensityOfTheSheetItRepeats) {
  for (const auto& [rows, cols] : {std::pair{2, 5}, std::pair{3, 3}, std::pair{6, 6}}) {
    const SquareMailOptions o = small_square(rows, cols);
    const double period = chainmail_square_period(o);
    SCOPED_TRACE(testing::Message() << "square " << rows << " x " << cols);
    EXPECT_NEAR(measure_swatch_structure(chainmail_square(o)).density, 3 / (period * period), 1e-9);
  }
  std::vector<double> d;
  for (const auto& [rows, cols] : {std::pair{3, 3}, std::pair{2, 4}, std::pair{5, 6}})
    d.push_back(measure_swatch_structure(chainmail_4in1(small_4in1(rows, cols))).density);
  EXPECT_GT(d[0], 0);
  EXPECT_NEAR(d[1], d[0], 1e-9 * d[0]);
  EXPECT_NEAR(d[2], d[0], 1e-9 * d[0]);
  AppleOptions a;
  a.count = 24;
  const TriMesh apples = apple_layer(a);
  const SwatchStructure s = measure_swatch_structure(apples);
  EXPECT_GT(s.density, 0);
  EXPECT_EQ(s.density, measure_swatch_structure(apples).density);
}

// Every figure is the same whatever the thread count.
TEST(TextureStructure, SameFiguresWhateverTheThreadCount) {
  const TriMesh sheet = chainmail_square(small_square(4, 4));
  const SwatchStructure s = measure_swatch_structure(sheet);
  TriMesh out = test::mapped(sheet, [](const Vector3d& p) { return test::over_cylinder(p, 6); });
  StructureOptions so;
  so.swatch = &s;
  std::vector<StructureReport> r;
  for (const int threads : {1, 2}) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    r.push_back(measure_structure(out, so));
  }
  ASSERT_EQ(r[0].elements.size(), r[1].elements.size());
  EXPECT_EQ(r[0].linked_pairs, r[1].linked_pairs);
  for (size_t e = 0; e < r[0].elements.size(); ++e) {
    const ElementStructure &a = r[0].elements[e], &b = r[1].elements[e];
    EXPECT_EQ(a.links, b.links);
    EXPECT_EQ(a.defect, b.defect);
    EXPECT_EQ(a.opening, b.opening);
    EXPECT_EQ(a.fold, b.fold);
    EXPECT_EQ(a.size_ratio, b.size_ratio);
    EXPECT_EQ(a.aspect, b.aspect);
  }
}

TEST(TextureStructure, ThreadsHaveTwoEndsAndBreaksAreCounted) {
  WeaveOptions o;
  o.threads_x = 8;
  o.threads_y = 8;
  const TriMesh weave = plain_weave(o);
  const StructureReport r = measure_structure(weave);
  EXPECT_EQ(r.rings, 0);
  EXPECT_EQ(r.long_elements, 16);
  EXPECT_EQ(r.ends, 32);
  EXPECT_EQ(r.interior_ends, 0) << "every end of an unbroken sheet lies at its border";
  // Cut one warp thread in the middle: two more ends, both away from the border.
  std::vector<int> fc;
  const int n = connected_components(weave.F, weave.num_vertices(), fc);
  const auto groups = component_faces(fc, n);
  TriMesh cut;
  for (int c = 0; c < n; ++c) {
    TriMesh part = extract_faces(weave, groups[c]);
    if (c == 3) {
      // Split the thread into the faces left and right of x = 3.7 (two open pieces).
      std::vector<int> left, right;
      for (int f = 0; f < part.num_faces(); ++f) {
        const double x =
            (part.V(part.F(f, 0), 0) + part.V(part.F(f, 1), 0) + part.V(part.F(f, 2), 0)) / 3;
        (x < 3.7 ? left : right).push_back(f);
      }
      TriMesh a = extract_faces(part, left), b = extract_faces(part, right);
      b.V.col(0).array() += 0.3;  // a gap, so the pieces are separate elements
      append_mesh(a, b);
      part = a;
    }
    if (cut.empty())
      cut = part;
    else
      append_mesh(cut, part);
  }
  const StructureReport rc = measure_structure(cut);
  EXPECT_EQ(rc.long_elements, 17);
  EXPECT_EQ(rc.interior_ends, 2);
  // Threads are not counted per area (they join across seams): no density ratio.
  EXPECT_EQ(compare_structure(rc, measure_swatch_structure(weave), 1.0).density_ratio, 0.0);
  // Apples are not long.
  const StructureReport apples = measure_structure(apple_layer({}));
  EXPECT_EQ(apples.long_elements, 0);
  EXPECT_EQ(apples.rings, 0);
}

// Studs (12-face boxes 0.3 x 0.3 x 0.1, as tiles or scales are made) are compact: the edge path
// between a box's far corners zigzags to 0.7 (the box spans 0.44), over four times the width a
// tube of the box's area and that length would have, so they counted as threads (a surface job
// warned of threads cut short). A bar as long as the swatch stays long.
TEST(TextureStructure, CoarseBoxesAreCompactAndBarsLong) {
  const Eigen::Matrix3d stud = Vector3d(0.3, 0.3, 0.1).asDiagonal();
  TriMesh studs;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      append_mesh(studs, moved(test::unit_cube(), stud, Vector3d(i, j, 0)));
  const StructureReport r = measure_structure(studs);
  EXPECT_EQ(r.long_elements, 0);
  EXPECT_EQ(r.compact_elements, 25);
  const Eigen::Matrix3d bar = Vector3d(8, 0.3, 0.1).asDiagonal();
  TriMesh bars = moved(test::unit_cube(), bar, Vector3d::Zero());
  append_mesh(bars, moved(test::unit_cube(), bar, Vector3d(0, 1, 0)));
  EXPECT_EQ(measure_structure(bars).long_elements, 2);
}

// Vines in swatch-sized pieces measure 1 swatch vine; a section three times as long with three
// times the leaves measures about 3, at the swatch's leaves per length; one of its leaves
// taken away shows in that ratio.
TEST(TextureStructure, VineLengthsAreMeasuredInSwatchVines) {
  IvyOptions o;
  o.length = 2;
  o.leaves = 2;
  const TriMesh swatch = ivy_section(o);
  const SwatchStructure ref = measure_swatch_structure(swatch);
  EXPECT_EQ(ref.report.long_elements, 1);
  EXPECT_EQ(ref.report.compact_elements, 2);
  EXPECT_GT(ref.report.median_long_length, 2.0);  // along its wave
  const StructureComparison same = compare_structure(ref.report, ref, 1.0);
  EXPECT_DOUBLE_EQ(same.long_length_ratio, 1.0);
  EXPECT_DOUBLE_EQ(same.compact_per_length_ratio, 1.0);
  o.length = 6;
  o.leaves = 6;
  const TriMesh longer = ivy_section(o);
  const StructureComparison three = compare_structure(measure_structure(longer), ref, 1.0);
  EXPECT_NEAR(three.long_length_ratio, 3.0, 0.3);
  EXPECT_NEAR(three.compact_per_length_ratio, 1.0, 0.1);
  o.leaves = 5;
  const StructureComparison fewer = compare_structure(measure_structure(ivy_section(o)), ref, 1.0);
  EXPECT_NEAR(fewer.compact_per_length_ratio / three.compact_per_length_ratio, 5.0 / 6, 0.02);
  // Twice the size, measured at that scale: the same figures.
  TriMesh big = longer;
  big.V *= 2;
  const StructureComparison scaled = compare_structure(measure_structure(big), ref, 2.0);
  EXPECT_NEAR(scaled.long_length_ratio, three.long_length_ratio, 1e-9);
  EXPECT_NEAR(scaled.compact_per_length_ratio, three.compact_per_length_ratio, 1e-9);
  // Without long elements there is nothing to compare.
  EXPECT_EQ(compare_structure(measure_structure(apple_layer({})), ref, 1.0).long_length_ratio, 0.0);
}

// A thread closed on itself (round a cup's body) is a long element without ends, as long as its
// loop, and not a ring; threads are measured in swatch threads, at a scale found from their
// widths when not given (the areas of welded threads follow their lengths, not the scale).
TEST(TextureStructure, ClosedThreadsHaveNoEndsAndLengthsCountInSwatchThreads) {
  WeaveOptions o;
  o.threads_x = o.threads_y = 6;
  const TriMesh weave = plain_weave(o);
  const SwatchStructure swatch = measure_swatch_structure(weave);
  TriMesh loop = test::planar_tube(
      [](double t) { return Vector2d(30 + 20 * std::cos(t), 20 * std::sin(t)); }, 0.15, 512, 10);
  set_single_kind(loop, "thread_x");
  TriMesh mesh = weave;
  append_mesh(mesh, loop);
  StructureOptions so;
  so.automatic_border = false;  // every end counts
  so.swatch = &swatch;
  const StructureReport r = measure_structure(mesh, so);
  EXPECT_EQ(r.rings, 0);
  EXPECT_EQ(r.long_elements, 13);
  EXPECT_EQ(r.closed_long_elements, 1);
  EXPECT_EQ(r.ends, 24);
  EXPECT_EQ(r.interior_ends, 24);
  ASSERT_EQ(r.elements.size(), 13u);
  const ElementStructure& closed = r.elements.back();
  EXPECT_TRUE(closed.closed);
  EXPECT_FALSE(closed.ring);
  EXPECT_NEAR(closed.length, 2 * M_PI * 20, 0.5);
  EXPECT_NEAR(closed.width, 0.3, 0.01);
  EXPECT_EQ(closed.interior_ends, 0);
  // The sheet against itself is one swatch thread long, and so it is twice as large.
  so.automatic_border = true;
  const StructureComparison self = compare_structure(measure_structure(weave, so), swatch);
  EXPECT_NEAR(self.long_length_ratio, 1.0, 1e-6);
  TriMesh twice = weave;
  twice.V *= 2;
  const StructureReport big = measure_structure(twice, so);
  EXPECT_NEAR(big.linear_scale, 2.0, 1e-6);
  const StructureComparison c = compare_structure(big, swatch);
  EXPECT_NEAR(c.long_length_ratio, 1.0, 1e-6);
  // Interior ends per swatch unit squared: the same as the sheet's own.
  EXPECT_NEAR(c.interior_ends_per_swatch_area, self.interior_ends_per_swatch_area, 1e-9);
}

TEST(TextureStructure, BaseBoundaryDecidesTheInteriorOfACurvedResult) {
  // Rings standing on an open half cylinder: those near its straight edges are border ones.
  const TriMesh grid = test::plane_grid(10, 10, 10, 10);
  TriMesh base = grid;
  for (int v = 0; v < base.num_vertices(); ++v) {
    const double a = grid.V(v, 0) / 10.0 * M_PI;
    base.V.row(v) << 5 * std::cos(a), grid.V(v, 1), 5 * std::sin(a);
  }
  StructureOptions so;
  so.automatic_border = false;
  so.border = mesh_border(base.V, base.F);
  ASSERT_EQ(so.border.kind, TextureBorder::Kind::Segments);
  TriMesh rings;
  const TriMesh ring = test::torus(0.5, 0.1, 24, 6);
  for (int i = 0; i < 5; ++i) {
    const double a = (0.1 + 0.2 * i) * M_PI;
    const TriMesh r =
        moved(ring, Eigen::Matrix3d::Identity(), Vector3d(5 * std::cos(a), 5.0, 5 * std::sin(a)));
    if (rings.empty())
      rings = r;
    else
      append_mesh(rings, r);
  }
  so.interior_margin = 2.0;
  const StructureReport r = measure_structure(rings, so);
  EXPECT_EQ(r.rings, 5);
  // y = 5 is 5 from the ends y = 0, 10; the first and last ring are ~1.6 from the edges x.
  EXPECT_EQ(r.interior_rings, 3);
  EXPECT_FALSE(r.elements[0].interior);
  EXPECT_TRUE(r.elements[2].interior);
  // Closed base: no border at all.
  EXPECT_EQ(mesh_border(test::unit_cube().V, test::unit_cube().F).kind, TextureBorder::Kind::None);
}

TEST(SelfIntersection, FoldedRingIsFoundAndNeighboursAreNot) {
  const TriMesh sheet = chain(3);
  EXPECT_TRUE(self_intersecting_components(sheet.V, sheet.F).empty());
  // Press one side of the middle ring through its other side.
  TriMesh folded = sheet;
  std::vector<int> fc;
  connected_components(folded.F, folded.num_vertices(), fc);
  for (int f = 0; f < folded.num_faces(); ++f)
    if (fc[f] == 1)
      for (int k = 0; k < 3; ++k) {
        const int v = folded.F(f, k);
        if (folded.V(v, 0) > 1.6 + 0.2) folded.V(v, 0) = 1.6 - (folded.V(v, 0) - 1.6);
      }
  const std::vector<int> self = self_intersecting_components(folded.V, folded.F);
  ASSERT_EQ(self.size(), 1u);
  EXPECT_EQ(self[0], 1);
}

TEST(TextureStructure, OptionsValidateRejectsFewBinsAndNegativeFigures) {
  StructureOptions so;
  EXPECT_NO_THROW(so.validate());
  so.loop_bins = 4;
  EXPECT_THROW(so.validate(), InvalidInput);
  EXPECT_THROW(measure_structure(chain(2), so), InvalidInput);
  so = StructureOptions{};
  so.end_margin = -1;
  EXPECT_THROW(so.validate(), InvalidInput);
  so = StructureOptions{};
  so.linear_scale = std::nan("");
  EXPECT_THROW(so.validate(), InvalidInput);
}

}  // namespace
}  // namespace mq
