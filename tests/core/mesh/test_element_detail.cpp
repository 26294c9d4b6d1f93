// A swatch at lower detail (core/mesh/element_detail): every element keeps its topology (a ring
// stays a closed torus with its hole), its bounding box and its kind, linked rings stay linked
// with the same linking number and nothing comes to intersect, each element is cut to the share
// of faces asked, and the result does not depend on the thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstdlib>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/element_detail.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/linking_number.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "tests/test_support.h"

namespace mq {
namespace {

struct Elements {
  std::vector<TriMesh> parts;
};

Elements split(const TriMesh& mesh) {
  std::vector<int> face_component;
  const int n = connected_components(mesh.F, mesh.num_vertices(), face_component);
  Elements e;
  for (const std::vector<int>& faces : component_faces(face_component, n))
    e.parts.push_back(extract_faces(mesh, faces));
  return e;
}

// Closed (every edge in two faces), manifold, of the given Euler characteristic.
void expect_closed_with_euler(const TriMesh& m, int euler) {
  const EdgeTopology topo = edge_topology(m.F, m.num_vertices());
  for (int e = 0; e < topo.num_edges(); ++e) ASSERT_EQ(topo.edge_faces.degree(e), 2);
  EXPECT_EQ(m.num_vertices() - topo.num_edges() + m.num_faces(), euler);
}

// The linking numbers of every pair of rings whose boxes overlap (the others cannot link).
std::vector<int> pair_links(const Elements& e) {
  std::vector<Loop> loops;
  for (const TriMesh& r : e.parts) {
    const std::optional<Loop> loop = ring_centre_loop(r.V, r.F);
    EXPECT_TRUE(loop.has_value());
    loops.push_back(loop.value_or(Loop{}));
  }
  std::vector<int> links;
  for (size_t i = 0; i < loops.size(); ++i)
    for (size_t j = i + 1; j < loops.size(); ++j) {
      const BoundingBox a = bounding_box(e.parts[i].V), b = bounding_box(e.parts[j].V);
      if ((a.max.array() < b.min.array()).any() || (b.max.array() < a.min.array()).any()) continue;
      links.push_back(std::abs(linking_number(loops[i], loops[j])));  // loops' sense is arbitrary
    }
  return links;
}

TEST(ElementDetail, RingsStayClosedToriLinkedAsBeforeAndApart) {
  ChainMailOptions cm;
  cm.rows = 3;
  cm.cols = 3;
  const TriMesh swatch = chainmail_4in1(cm);  // 9 rings of 1,152 faces
  ElementDetailOptions o;
  o.detail = 0.1;
  const ElementDetail d = reduce_element_detail(swatch, o);
  EXPECT_EQ(d.elements, 9);
  EXPECT_EQ(d.median_faces_before, 1152);
  // A tenth of the faces, give or take the last collapses a constraint refused.
  EXPECT_LE(d.max_faces_after, 130);
  EXPECT_GE(d.median_faces_after, 100);
  const Elements before = split(swatch), after = split(d.mesh);
  ASSERT_EQ(after.parts.size(), before.parts.size());
  for (size_t i = 0; i < after.parts.size(); ++i) {
    SCOPED_TRACE(i);
    expect_closed_with_euler(after.parts[i], 0);  // a torus: the hole is kept
    const BoundingBox a = bounding_box(before.parts[i].V), b = bounding_box(after.parts[i].V);
    EXPECT_EQ(a.min, b.min);
    EXPECT_EQ(a.max, b.max);
    EXPECT_TRUE(self_intersecting_components(after.parts[i].V, after.parts[i].F).empty());
  }
  const std::vector<int> links = pair_links(before);
  int linked = 0;
  for (const int l : links) linked += l != 0;
  EXPECT_GE(linked, 8);  // the 3 x 3 sheet's links, checked on the input first
  EXPECT_EQ(pair_links(after), links);
  for (size_t i = 0; i < after.parts.size(); ++i)
    for (size_t j = i + 1; j < after.parts.size(); ++j)
      EXPECT_FALSE(meshes_intersect(after.parts[i], after.parts[j])) << i << " " << j;
}

// Rings of 288 faces at a tenth: 29 faces fold a wire through itself; the group is given more
// faces (x1.6 a round) until nothing intersects, and the links stay.
TEST(ElementDetail, TooCoarseRingsAreKeptFinerUntilNothingIntersects) {
  ChainMailOptions cm;
  cm.rows = 3;
  cm.cols = 3;
  cm.ring_segments = 24;
  cm.wire_segments = 6;
  const TriMesh swatch = chainmail_4in1(cm);
  ElementDetailOptions o;
  o.detail = 0.1;
  const ElementDetail d = reduce_element_detail(swatch, o);
  EXPECT_EQ(d.groups, 1);
  EXPECT_EQ(d.raised, 1);
  EXPECT_GT(d.median_faces_after, 29);
  EXPECT_LT(d.median_faces_after, 288);
  EXPECT_TRUE(self_intersecting_components(d.mesh.V, d.mesh.F).empty());
  EXPECT_TRUE(intersecting_face_pairs(d.mesh.V, d.mesh.F).empty());
  EXPECT_EQ(pair_links(split(d.mesh)), pair_links(split(swatch)));
}

TEST(ElementDetail, KindsAndOrderAreKeptAndFullDetailIsTheSwatch) {
  SquareMailOptions sq;
  sq.rows = 2;
  sq.cols = 2;
  const TriMesh swatch = chainmail_square(sq);  // rings then connectors, two kinds
  ASSERT_TRUE(has_kinds(swatch));
  ElementDetailOptions o;
  const ElementDetail same = reduce_element_detail(swatch, o);
  EXPECT_EQ(same.mesh.V, swatch.V);
  EXPECT_EQ(same.mesh.F, swatch.F);
  EXPECT_EQ(same.mesh.face_kind, swatch.face_kind);
  o.detail = 0.2;
  const ElementDetail d = reduce_element_detail(swatch, o);
  EXPECT_EQ(d.mesh.kinds, swatch.kinds);
  const Elements before = split(swatch), after = split(d.mesh);
  ASSERT_EQ(after.parts.size(), before.parts.size());
  for (size_t i = 0; i < after.parts.size(); ++i) {
    ASSERT_FALSE(after.parts[i].face_kind.empty());
    // One kind per element, the one it had.
    for (const int k : after.parts[i].face_kind) EXPECT_EQ(k, before.parts[i].face_kind[0]);
    EXPECT_LT(after.parts[i].num_faces(), before.parts[i].num_faces() / 3);
  }
}

TEST(ElementDetail, SmallElementsKeepTheirFloorAndTheResultIsTheSameOnAnyThreadCount) {
  ChainMailOptions cm;
  cm.rows = 4;
  cm.cols = 4;
  cm.ring_segments = 8;
  cm.wire_segments = 4;  // 64 faces a ring
  const TriMesh swatch = chainmail_4in1(cm);
  ElementDetailOptions o;
  o.detail = 0.05;
  o.min_faces = 40;
  ElementDetail first;
  for (const int threads : {1, 2, 4}) {
    tbb::task_arena arena(threads);
    ElementDetail d;
    arena.execute([&] { d = reduce_element_detail(swatch, o); });
    if (threads == 1) {
      first = d;
      EXPECT_GE(d.max_faces_after, 40);
      EXPECT_LE(d.max_faces_after, 64);
      for (const TriMesh& r : split(d.mesh).parts) expect_closed_with_euler(r, 0);
    } else {
      EXPECT_EQ(d.mesh.V, first.mesh.V);
      EXPECT_EQ(d.mesh.F, first.mesh.F);
    }
  }
}

TEST(ElementDetail, OptionsOutOfRangeAreRefused) {
  const TriMesh swatch = test::unit_cube();
  for (const double detail : {0.0, -0.5, 1.5, std::nan("")}) {
    ElementDetailOptions o;
    o.detail = detail;
    EXPECT_THROW(reduce_element_detail(swatch, o), InvalidInput) << detail;
  }
  ElementDetailOptions o;
  o.min_faces = 3;
  EXPECT_THROW(reduce_element_detail(swatch, o), InvalidInput);
  TriMesh bad = swatch;
  bad.V(0, 0) = std::nan("");
  EXPECT_THROW(reduce_element_detail(bad, ElementDetailOptions{}), InvalidInput);
}

}  // namespace
}  // namespace mq
