// Element kinds (core/mesh/element_kinds.h) from files and generators, through the writers and the
// quilting, and the OBJ/PLY element labels an artist's tools read (issue 15).
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/quilt_elements.h"
#include "core/planar/swatch_generators.h"
#include "host/translation_cost_evaluator.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Faces per kind name.
std::map<std::string, int> faces_per_kind(const TriMesh& m) {
  std::map<std::string, int> n;
  for (const int k : m.face_kind) ++n[m.kinds[static_cast<size_t>(k)]];
  return n;
}

// Elements per kind name, by connected component.
std::map<std::string, int> elements_per_kind(const TriMesh& m) {
  const ElementLabels l = element_labels(m);
  std::map<std::string, int> n;
  for (const int k : l.element_kind) ++n[l.kinds[static_cast<size_t>(k)]];
  return n;
}

TEST(ElementKinds, GeneratorsNameTheirElements) {
  ChainMailOptions mail;
  mail.rows = 2;
  mail.cols = 3;
  EXPECT_EQ(elements_per_kind(chainmail_4in1(mail)), (std::map<std::string, int>{{"ring", 6}}));
  WeaveOptions weave;
  weave.threads_x = 3;
  weave.threads_y = 4;
  EXPECT_EQ(elements_per_kind(plain_weave(weave)),
            (std::map<std::string, int>{{"thread_x", 3}, {"thread_y", 4}}));
  AppleOptions apples;
  apples.count = 5;
  EXPECT_EQ(elements_per_kind(apple_layer(apples)), (std::map<std::string, int>{{"apple", 5}}));
  IvyOptions ivy;
  ivy.leaves = 4;
  EXPECT_EQ(elements_per_kind(ivy_section(ivy)),
            (std::map<std::string, int>{{"leaf", 4}, {"vine", 1}}));
}

TEST(ElementKinds, ObjMaterialsNameKindsBeforeGroups) {
  const std::string dir = test::temp_dir();
  // Two triangles in group a with material m1, one in group b without a material change, one
  // with group c and material (null) (as some exporters write), one before any name.
  test::spit(dir + "/k.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
             "g a\nusemtl m1\nf 1 2 3\nf 1 3 2\n"
             "g b\nf 2 3 1\n"
             "o c\nusemtl (null)\nf 3 1 2\n");
  const TriMesh m = read_mesh(dir + "/k.obj");
  ASSERT_TRUE(has_kinds(m));
  ASSERT_EQ(m.face_kind.size(), 5u);
  const auto name = [&](int f) {
    return m.kinds[static_cast<size_t>(m.face_kind[static_cast<size_t>(f)])];
  };
  EXPECT_EQ(name(0), kDefaultKind);
  EXPECT_EQ(name(1), "m1");
  EXPECT_EQ(name(2), "m1");
  EXPECT_EQ(name(3), "m1");  // g b keeps material m1
  EXPECT_EQ(name(4), "c");   // (null) is no material: the object name
  // A file with no names has no kinds.
  test::spit(dir + "/plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_FALSE(has_kinds(read_mesh(dir + "/plain.obj")));
  // The shared leaf swatches name theirs.
  const TriMesh rose = read_mesh(test::shared_data("swatch/leaf_rose_311.obj"));
  ASSERT_TRUE(has_kinds(rose));
  EXPECT_EQ(rose.kinds.size(), 1u);
}

TEST(ElementKinds, ObjGroupsByElementKindOrNoneRoundTrip) {
  const std::string dir = test::temp_dir();
  IvyOptions ivy;
  ivy.leaves = 5;
  const TriMesh mesh = ivy_section(ivy);
  for (const ElementGroups g : {ElementGroups::Element, ElementGroups::Kind, ElementGroups::None}) {
    WriteOptions o;
    o.write_elements = true;
    o.write_normals = true;
    o.groups = g;
    write_mesh(dir + "/ivy.obj", mesh, o);
    const std::string text = test::slurp(dir + "/ivy.obj");
    int objects = 0;
    std::set<std::string> names, materials;
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
      if (line.rfind("o ", 0) == 0) {
        ++objects;
        names.insert(line.substr(2));
      }
      if (line.rfind("usemtl ", 0) == 0) materials.insert(line.substr(7));
    }
    EXPECT_NE(text.find("mtllib ivy.mtl\n"), std::string::npos);
    EXPECT_EQ(materials, (std::set<std::string>{"leaf", "vine"}));
    if (g == ElementGroups::Element) {
      EXPECT_EQ(objects, 6);
      EXPECT_TRUE(names.count("vine_0") && names.count("leaf_5")) << text.substr(0, 200);
    } else if (g == ElementGroups::Kind) {
      EXPECT_EQ(names, (std::set<std::string>{"leaf", "vine"}));
    } else {
      EXPECT_EQ(objects, 0);
    }
    // The .mtl defines every material used.
    const std::string mtl = test::slurp(dir + "/ivy.mtl");
    EXPECT_NE(mtl.find("newmtl leaf\n"), std::string::npos);
    EXPECT_NE(mtl.find("newmtl vine\n"), std::string::npos);
    // Read back: same faces (as a set), same kinds per face count.
    const TriMesh back = read_mesh(dir + "/ivy.obj");
    EXPECT_EQ(back.num_faces(), mesh.num_faces());
    EXPECT_EQ(faces_per_kind(back), faces_per_kind(mesh));
    EXPECT_EQ(elements_per_kind(back), elements_per_kind(mesh));
  }
}

// The OBJ rows are formatted in parallel chunks (8,192 rows, windows of 8): an element whose
// faces straddle a chunk boundary still gets one "o" line, and the bytes do not depend on the
// thread count.
TEST(ElementKinds, ObjWrittenInChunksIsTheSameOnAnyThreadCount) {
  const std::string dir = test::temp_dir();
  ChainMailOptions cm;
  cm.rows = 16;
  cm.cols = 16;
  cm.ring_segments = 24;
  cm.wire_segments = 8;
  const TriMesh mesh = chainmail_4in1(cm);  // 256 rings of 384 faces: 12 chunks of faces
  ASSERT_GT(mesh.num_faces(), 8 * 8192);
  WriteOptions o;
  o.write_elements = true;
  o.write_normals = true;
  std::string first;
  for (const int threads : {1, 2, 4}) {
    tbb::task_arena arena(threads);
    arena.execute([&] { write_mesh(dir + "/mail.obj", mesh, o); });
    const std::string text = test::slurp(dir + "/mail.obj");
    if (threads == 1) {
      first = text;
      std::set<std::string> names;
      int objects = 0;
      std::istringstream lines(text);
      std::string line;
      while (std::getline(lines, line))
        if (line.rfind("o ", 0) == 0) {
          ++objects;
          names.insert(line.substr(2));
        }
      EXPECT_EQ(objects, 256);
      EXPECT_EQ(names.size(), 256u);
      const TriMesh back = read_mesh(dir + "/mail.obj");
      EXPECT_EQ(back.num_faces(), mesh.num_faces());
      EXPECT_EQ(elements_per_kind(back), elements_per_kind(mesh));
    } else {
      EXPECT_TRUE(text == first) << threads << " threads wrote different bytes";
    }
  }
}

TEST(ElementKinds, PlyCarriesElementIdAndKindPerVertex) {
  const std::string dir = test::temp_dir();
  WeaveOptions weave;
  weave.threads_x = 2;
  weave.threads_y = 3;
  const TriMesh mesh = plain_weave(weave);
  for (const bool binary : {true, false}) {
    WriteOptions o;
    o.write_elements = true;
    o.write_normals = true;
    o.binary = binary;
    write_mesh(dir + "/w.ply", mesh, o);
    const std::string text = test::slurp(dir + "/w.ply");
    EXPECT_NE(text.find("property int element_id\nproperty int kind\n"), std::string::npos);
    EXPECT_NE(text.find("comment kind 0 thread_x\n"), std::string::npos);
    EXPECT_NE(text.find("comment kind 1 thread_y\n"), std::string::npos);
    EXPECT_NE(text.find("comment kind_material 1 "), std::string::npos);
    const TriMesh back = read_mesh(dir + "/w.ply");
    EXPECT_EQ(faces_per_kind(back), faces_per_kind(mesh));
    EXPECT_EQ(back.N.rows(), back.V.rows());
  }
  // element_id is the component number in face order: check it in the ASCII file.
  WriteOptions o;
  o.write_elements = true;
  o.binary = false;
  write_mesh(dir + "/a.ply", mesh, o);
  std::istringstream in(test::slurp(dir + "/a.ply"));
  std::string line;
  while (std::getline(in, line) && line != "end_header") {
  }
  std::vector<int> vertex_element;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    double x, y, z;
    int e, k;
    in >> x >> y >> z >> e >> k;
    vertex_element.push_back(e);
  }
  std::vector<int> fc;
  connected_components(mesh.F, mesh.num_vertices(), fc);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(vertex_element[static_cast<size_t>(mesh.F(f, k))], fc[static_cast<size_t>(f)]);
}

TEST(ElementKinds, MajorityOfFacesGivesAnElementItsKindAndBadKindsAreRefused) {
  TriMesh m = test::unit_cube();
  m.kinds = {"a", "b"};
  m.face_kind.assign(12, 1);
  m.face_kind[0] = m.face_kind[1] = 0;
  std::vector<int> fc;
  const int n = connected_components(m.F, m.num_vertices(), fc);
  EXPECT_EQ(component_kinds(m, fc, n), std::vector<int>{1});
  const std::vector<Element> elements = split_elements(m);
  ASSERT_EQ(elements.size(), 1u);
  EXPECT_EQ(elements[0].kind, 1);
  m.face_kind[3] = 7;
  EXPECT_THROW(ensure_kinds(m), InvalidInput);
  EXPECT_THROW(write_mesh(test::temp_dir() + "/bad.obj", m), InvalidInput);
}

TEST(ElementKinds, AppendMergesKindsByName) {
  TriMesh a = test::unit_cube(), b = test::unit_cube(), c = test::unit_cube();
  set_single_kind(a, "x");
  set_single_kind(b, "y");
  TriMesh sum;
  append_mesh(sum, a);
  append_mesh(sum, b);
  append_mesh(sum, a);
  append_mesh(sum, c);  // no kinds: kDefaultKind
  EXPECT_EQ(sum.kinds, (std::vector<std::string>{"x", "y", kDefaultKind}));
  EXPECT_EQ(faces_per_kind(sum),
            (std::map<std::string, int>{{"x", 24}, {"y", 12}, {kDefaultKind, 12}}));
}

TEST(ElementKinds, PlanarQuiltingKeepsKindsOfIvyAndWeave) {
  auto evaluator = make_translation_cost_evaluator(Device::Cpu);
  IvyOptions ivy;
  ivy.leaves = 6;
  ivy.length = 6;
  PlanarQuiltingOptions o;
  o.length = 12;
  o.width = 8;
  const TriMesh out = quilt_plane(ivy_section(ivy), o, *evaluator);
  ASSERT_TRUE(has_kinds(out));
  const auto per = elements_per_kind(out);
  EXPECT_GE(per.at("vine"), 1);
  EXPECT_GE(per.at("leaf"), 6);
  EXPECT_EQ(per.size(), 2u);
  // Labels follow the geometry: every leaf element is smaller than every vine element (a vine
  // labelled leaf or the reverse would break this).
  const ElementLabels l = element_labels(out);
  std::vector<int> faces(static_cast<size_t>(l.count), 0);
  for (const int e : l.face_element) ++faces[static_cast<size_t>(e)];
  int max_leaf = 0, min_vine = 1 << 30;
  for (int e = 0; e < l.count; ++e) {
    const bool leaf =
        l.kinds[static_cast<size_t>(l.element_kind[static_cast<size_t>(e)])] == "leaf";
    (leaf ? max_leaf : min_vine) = leaf ? std::max(max_leaf, faces[static_cast<size_t>(e)])
                                        : std::min(min_vine, faces[static_cast<size_t>(e)]);
  }
  EXPECT_LT(max_leaf, min_vine);
}

// Kinds whose names are equal once written (two named "element", one of them the default for an
// unnamed kind; "a b" beside "a_b"; "kind_1" beside "kind" and a second "kind") get distinct
// names in every format, so an OBJ reads back with as many kinds as were written (issue 28).
TEST(ElementKinds, NamesStayDistinctInEveryFormat) {
  EXPECT_EQ(unique_kind_names({"element", ""}), (std::vector<std::string>{"element", "element_2"}));
  EXPECT_EQ(unique_kind_names({"a b", "a_b"}), (std::vector<std::string>{"a_b", "a_b_2"}));
  EXPECT_EQ(unique_kind_names({"kind", "kind_2", "kind"}),
            (std::vector<std::string>{"kind", "kind_2", "kind_3"}));
  EXPECT_EQ(unique_kind_names({"ring", "leaf"}), (std::vector<std::string>{"ring", "leaf"}));

  const std::string dir = test::temp_dir();
  // Three separate triangles, one per kind; two kinds named alike once sanitised.
  TriMesh mesh;
  mesh.V.resize(9, 3);
  mesh.F.resize(3, 3);
  for (int t = 0; t < 3; ++t) {
    mesh.V.row(3 * t) << 3.0 * t, 0, 0;
    mesh.V.row(3 * t + 1) << 3.0 * t + 1, 0, 0;
    mesh.V.row(3 * t + 2) << 3.0 * t, 1, 0;
    mesh.F.row(t) << 3 * t, 3 * t + 1, 3 * t + 2;
  }
  mesh.kinds = {"a b", "a_b", "element"};
  mesh.face_kind = {0, 1, 2};
  WriteOptions o;
  o.write_elements = true;
  for (const char* name : {"k.obj", "k.ply"}) {
    write_mesh(dir + "/" + name, mesh, o);
    const TriMesh back = read_mesh(dir + "/" + name);
    EXPECT_EQ(std::set<std::string>(back.kinds.begin(), back.kinds.end()).size(), 3u) << name;
    EXPECT_EQ(faces_per_kind(back).size(), 3u) << name;
  }
  const std::string mtl = test::slurp(dir + "/k.mtl");
  EXPECT_NE(mtl.find("newmtl a_b\n"), std::string::npos);
  EXPECT_NE(mtl.find("newmtl a_b_2\n"), std::string::npos);
  const std::string ply = test::slurp(dir + "/k.ply");
  EXPECT_NE(ply.find("comment kind 1 a_b_2\n"), std::string::npos);
}

}  // namespace
}  // namespace mq
