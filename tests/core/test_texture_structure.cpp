#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/mesh_intersections.h"
#include "core/mesh_topology.h"
#include "core/swatch_generators.h"
#include "core/texture_structure.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TriMesh moved(TriMesh m, const Eigen::Matrix3d& R, const Vector3d& t) {
  for (int v = 0; v < m.num_vertices(); ++v) m.V.row(v) = (R * m.V.row(v).transpose() + t);
  return m;
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

// A ring the map stretched is counted against the swatch's element size at the output's
// scale: one ring of a sheet stretched 2x along x, the sheet itself scaled by 3.
TEST(TextureStructure, StretchedElementsAreCountedAgainstTheSwatchSize) {
  ChainMailOptions o;
  o.rows = 6;
  o.cols = 6;
  const TriMesh sheet = chainmail_4in1(o);
  const SwatchStructure s = measure_swatch_structure(sheet);
  TriMesh out = moved(sheet, 3.0 * Eigen::Matrix3d::Identity(), Vector3d::Zero());
  const StructureComparison plain = compare_structure(measure_structure(out), s, 3.0);
  EXPECT_EQ(plain.stretched, 0);
  EXPECT_NEAR(plain.largest_size, 1.0, 0.02);  // every ring has the swatch's size
  std::vector<int> fc;
  const int n = connected_components(out.F, out.num_vertices(), fc);
  const auto groups = component_faces(fc, n);
  TriMesh ring = extract_faces(out, groups[14]);
  const double cx = ring.V.col(0).mean();
  ring.V.col(0) = ((ring.V.col(0).array() - cx) * 2.0 + cx).matrix();
  std::vector<int> others;
  for (int c = 0; c < n; ++c)
    if (c != 14) others.insert(others.end(), groups[c].begin(), groups[c].end());
  out = extract_faces(out, others);
  append_mesh(out, ring);
  const StructureComparison one = compare_structure(measure_structure(out), s, 3.0);
  EXPECT_EQ(one.stretched, 1);
  EXPECT_GT(one.largest_size, 1.7);
  EXPECT_LT(one.largest_size, 2.05);
  // Threads are not compact elements: a weave reports no stretch.
  const TriMesh weave = plain_weave();
  const StructureComparison w =
      compare_structure(measure_structure(weave), measure_swatch_structure(weave), 1.0);
  EXPECT_EQ(w.stretched, 0);
  EXPECT_EQ(w.largest_size, 0.0);
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

}  // namespace
}  // namespace mq
