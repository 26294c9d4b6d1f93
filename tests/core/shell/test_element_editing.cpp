// Editing a saved quilt element by element (issue 25): selection by id, kind and region,
// removal keeping the rest (and their local coordinates) in order, materials and palettes.
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"
#include "core/shell/element_editing.h"
#include "core/shell/follow_base.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Ten unit boxes in a row over a 10 x 1 sheet, at x = 0.25, 1.25, ..., kinds a, b, a, b, ...
SavedQuilt row_of_boxes() {
  SurfaceQuilt quilt;
  quilt.input_base = test::plane_grid(10.0, 1.0, 20, 2);
  quilt.shell_height = 0.5;
  for (int v = 0; v < quilt.input_base.num_vertices(); ++v) quilt.input_vertex.push_back(v);
  TriMesh output;
  output.kinds = {"a", "b"};
  for (int i = 0; i < 10; ++i) {
    TriMesh box = test::unit_cube();
    box.V *= 0.5;
    box.V.col(0).array() += i;
    box.V.col(2).array() += 0.01;
    box.kinds = {i % 2 ? "b" : "a"};
    box.face_kind.assign(static_cast<size_t>(box.num_faces()), 0);
    TriMesh merged = output;
    append_mesh(merged, box);
    merged.kinds = output.kinds;
    merged.face_kind = output.face_kind;
    for (int f = 0; f < box.num_faces(); ++f) merged.face_kind.push_back(i % 2);
    output = merged;
  }
  SavedQuiltHeader header;
  header.base = fingerprint(quilt.input_base);
  return make_saved_quilt(quilt, output, header);
}

int count(const std::vector<char>& flags) {
  return static_cast<int>(std::count(flags.begin(), flags.end(), 1));
}

TEST(ElementEditing, SelectsByIdKindAndRegion) {
  const SavedQuilt q = row_of_boxes();
  EXPECT_EQ(count(select_elements(q, {})), 10);
  ElementSelection s;
  s.ids = {1, 2, 3};
  EXPECT_EQ(count(select_elements(q, s)), 3);
  s.kind = "b";
  EXPECT_EQ(select_elements(q, s), (std::vector<char>{0, 1, 0, 1, 0, 0, 0, 0, 0, 0}));
  ElementSelection region;
  region.sphere = true;
  region.centre = Vector3d(4.25, 0.25, 0.26);
  region.radius = 1.1;  // the centres at 3.25, 4.25, 5.25
  EXPECT_EQ(count(select_elements(q, region)), 3);
  region.box = true;
  region.lo = Vector3d(4, 0, 0);
  region.hi = Vector3d(10, 1, 1);
  EXPECT_EQ(count(select_elements(q, region)), 2);
  s = {};
  s.ids = {10};
  EXPECT_THROW(select_elements(q, s), InvalidInput);
  s = {};
  s.kind = "c";
  EXPECT_THROW(select_elements(q, s), InvalidInput);
  region.radius = -1;
  EXPECT_THROW(select_elements(q, region), InvalidInput);
}

TEST(ElementEditing, RemovalKeepsTheRestAndTheirPlaces) {
  SavedQuilt q = row_of_boxes();
  const SavedQuilt before = q;
  ElementSelection s;
  s.kind = "b";
  remove_elements(q, select_elements(q, s));
  EXPECT_EQ(q.output.num_faces(), 5 * 12);
  EXPECT_EQ(q.coords.size(), q.output.num_vertices());
  EXPECT_EQ(q.output.kinds, std::vector<std::string>{"a"});
  // The first kept box is the first box, vertex for vertex, with its local coordinates.
  EXPECT_EQ(q.output.V.topRows(8), before.output.V.topRows(8));
  EXPECT_EQ(q.coords.bary.topRows(8), before.coords.bary.topRows(8));
  // And it still follows the base: a lifted base lifts the kept boxes alike.
  MatrixX3d V = q.base.V;
  V.col(2).array() += 2.0;
  const TriMesh lifted = follow_base(q, V, {});
  EXPECT_NEAR((lifted.V.col(2) - q.output.V.col(2)).minCoeff(), 2.0, 1e-9);
  EXPECT_NEAR((lifted.V.col(2) - q.output.V.col(2)).maxCoeff(), 2.0, 1e-9);
}

TEST(ElementEditing, MaterialsAndSeededPalettes) {
  SavedQuilt q = row_of_boxes();
  ElementSelection s;
  s.ids = {0, 9};
  set_element_kind(q, select_elements(q, s), "color_ff8800");
  EXPECT_EQ(q.output.kinds.size(), 3u);
  EXPECT_EQ(q.output.kinds[static_cast<size_t>(q.output.face_kind[0])], "color_ff8800");
  EXPECT_EQ(q.output.kinds[static_cast<size_t>(q.output.face_kind[12])], "b");
  SavedQuilt p1 = row_of_boxes(), p2 = row_of_boxes(), p3 = row_of_boxes();
  assign_palette(p1, select_elements(p1, {}), 3, 7);
  assign_palette(p2, select_elements(p2, {}), 3, 7);
  assign_palette(p3, select_elements(p3, {}), 3, 8);
  EXPECT_EQ(p1.output.face_kind, p2.output.face_kind);
  EXPECT_EQ(p1.output.kinds, p2.output.kinds);
  EXPECT_TRUE(p1.output.face_kind != p3.output.face_kind || p1.output.kinds != p3.output.kinds);
  for (const std::string& k : p1.output.kinds)
    EXPECT_TRUE(k.rfind("a_", 0) == 0 || k.rfind("b_", 0) == 0) << k;
  EXPECT_THROW(assign_palette(p1, select_elements(p1, {}), 0, 1), InvalidInput);
}

}  // namespace
}  // namespace mq
