#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"
#include "tests/test_support.h"

namespace mq {
namespace {

namespace fs = std::filesystem;

struct Expected {
  int triangles;
  int referenced_vertices;
};

// Counts from ../shared/data/PROVENANCE.md; quad files store twice as many triangles.
std::map<std::string, Expected> expected_counts() {
  return {
      {"base/bunny_igl_7k.off", {6966, 3485}},
      {"base/stanford_bunny_70k.obj", {69451, 34834}},
      {"base/teapot_6k.obj", {6320, 3644}},
      {"base/spot_6k.obj", {5856, 2930}},
      {"base/fertility_genus4_9k.off", {9000, 4494}},
      {"base/knight_decimated_1k.off", {1000, 502}},
      {"base/lilium_7k.obj", {6590, 3389}},
      {"base/face_52k.obj", {51712, 25905}},
      {"base/venus_1.4k.off", {1418, 711}},
      {"base/venus_100k.off", {100000, 50002}},
      {"base/cup_mug_11k.off", {11340, 5668}},
      {"base/chair_gothic_512.off", {512, 857}},
      {"base/genus3_13k.off", {13312, 6652}},
      {"base/dragon_108k.off", {108588, 54296}},
      {"swatch/torus_576.off", {576, 288}},
      {"base/david_head_51k.obj", {51460, 25732}},
      {"base/ivy_brick_wall_84.obj", {84, 146}},
      {"base/wicker_chair_17k.obj", {16920, 8639}},
      {"base/bunny_npm_3.7k.obj", {3674, 1839}},
      {"swatch/chainmail3d_48rings_49k.obj", {49152, 24576}},
      {"swatch/chainlink_half_12k.obj", {11828, 5916}},
      {"swatch/leaf_rose_311.obj", {563, 376}},
      {"swatch/leaf_bacopa_128q.obj", {256, 130}},
      {"swatch/fruit_purse_240q.obj", {480, 242}},
      {"swatch/petal_lily_440q.obj", {880, 442}},
  };
}

int referenced_vertices(const TriMesh& m) {
  std::vector<char> used(static_cast<size_t>(m.num_vertices()), 0);
  for (Eigen::Index i = 0; i < m.F.size(); ++i) used[static_cast<size_t>(m.F.data()[i])] = 1;
  return static_cast<int>(std::count(used.begin(), used.end(), 1));
}

TEST(MeshIo, EveryMeshInSharedDataLoadsWithProvenanceCounts) {
  const std::map<std::string, Expected> expected = expected_counts();
  int checked = 0;
  for (const char* dir : {"base", "swatch"}) {
    for (const auto& entry : fs::directory_iterator(test::shared_data(dir))) {
      const std::string rel = std::string(dir) + "/" + entry.path().filename().string();
      SCOPED_TRACE(rel);
      const TriMesh m = read_mesh(entry.path().string());
      ASSERT_GT(m.num_faces(), 0);
      EXPECT_GE(m.F.minCoeff(), 0);
      EXPECT_LT(m.F.maxCoeff(), m.num_vertices());
      EXPECT_TRUE(m.V.allFinite());
      const auto it = expected.find(rel);
      ASSERT_NE(it, expected.end()) << "mesh missing from the expected table";
      EXPECT_EQ(m.num_faces(), it->second.triangles);
      EXPECT_EQ(referenced_vertices(m), it->second.referenced_vertices);
      ++checked;
    }
  }
  EXPECT_EQ(checked, static_cast<int>(expected.size()));
}

std::string write_text(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Asserts that reading `path` throws InvalidInput whose message starts with "path:LINE:" (when
// line > 0) or names the path (line == 0), and contains `what`.
void expect_read_error(const std::string& path, int line, const std::string& what) {
  try {
    read_mesh(path);
    ADD_FAILURE() << "no exception reading " << path;
  } catch (const InvalidInput& e) {
    const std::string msg = e.what();
    if (line > 0) {
      EXPECT_EQ(msg.rfind(path + ":" + std::to_string(line) + ": ", 0), 0u) << msg;
    } else {
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
    }
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

void expect_same_mesh(const TriMesh& a, const TriMesh& b) {
  ASSERT_EQ(a.V.rows(), b.V.rows());
  ASSERT_EQ(a.F.rows(), b.F.rows());
  EXPECT_TRUE(a.V == b.V);
  EXPECT_TRUE(a.F == b.F);
}

TEST(MeshIo, FormatFromExtensionIsCaseInsensitive) {
  EXPECT_EQ(mesh_format_from_path("a/b.obj"), MeshFormat::Obj);
  EXPECT_EQ(mesh_format_from_path("B.PLY"), MeshFormat::Ply);
  EXPECT_EQ(mesh_format_from_path("x.y/c.Off"), MeshFormat::Off);
  for (const std::string bad : {"mesh.stl", "mesh", "obj"}) {
    try {
      mesh_format_from_path(bad);
      ADD_FAILURE() << bad;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(MeshIo, MalformedInputNamesFileAndLine) {
  const std::string dir = test::temp_dir();
  // Truncated OFF: header promises 2 faces, the file ends after one.
  expect_read_error(
      write_text(dir, "trunc.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n"), 8,
      "expected 2 faces");
  expect_read_error(write_text(dir, "trunc_v.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n"), 5,
                    "expected 4 vertices");
  expect_read_error(write_text(dir, "trunc_line.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1"), 6,
                    "expected vertex index");
  // Out-of-range and zero indices.
  expect_read_error(write_text(dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), 4,
                    "vertex index 4 out of range");
  expect_read_error(write_text(dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), 4,
                    "vertex index 0");
  expect_read_error(write_text(dir, "neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"), 4,
                    "vertex index -4 out of range");
  expect_read_error(write_text(dir, "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), 6,
                    "vertex index 3 out of range");
  expect_read_error(
      write_text(dir, "badn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n"), 5,
      "normal index 2 out of range");
  // Non-finite and malformed numbers.
  expect_read_error(write_text(dir, "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), 2,
                    "non-finite");
  expect_read_error(write_text(dir, "inf.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n"), 4,
                    "non-finite");
  expect_read_error(write_text(dir, "num.obj", "v 0 0 0\nv 1.0x 0 0\nv 0 1 0\nf 1 2 3\n"), 2,
                    "malformed number");
  expect_read_error(write_text(dir, "short.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"), 2,
                    "expected vertex coordinate");
  expect_read_error(write_text(dir, "idx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3a\n"), 4,
                    "malformed integer");
  // Faces with fewer than three vertices.
  expect_read_error(write_text(dir, "two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), 4,
                    "face with 2 vertices");
  expect_read_error(write_text(dir, "two.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"), 6,
                    "face with 2 vertices");
  // Empty, faceless, missing, unknown.
  expect_read_error(write_text(dir, "empty.obj", ""), 1, "empty file");
  expect_read_error(write_text(dir, "empty.off", ""), 1, "empty file");
  expect_read_error(write_text(dir, "empty.ply", ""), 1, "empty file");
  expect_read_error(write_text(dir, "nofaces.obj", "v 0 0 0\nv 1 0 0\n"), 0, "no faces");
  expect_read_error(write_text(dir, "nofaces.off", "OFF\n1 0 0\n0 0 0\n"), 0, "no faces");
  expect_read_error(write_text(dir, "header.off", "3 1 0\n0 0 0\n"), 1, "missing OFF header");
  expect_read_error(dir + "/does_not_exist.obj", 0, "cannot open");
  expect_read_error(write_text(dir, "mesh.stl", "solid x\n"), 0, "unknown mesh format");
  // A directory given for a mesh (no extension, or a mesh's) says so, not "format ''".
  std::filesystem::create_directories(dir + "/folder");
  std::filesystem::create_directories(dir + "/folder.obj");
  expect_read_error(dir + "/folder", 0, "is a directory, not a mesh file");
  expect_read_error(dir + "/folder.obj", 0, "is a directory");
  // PLY header problems.
  expect_read_error(write_text(dir, "type.ply",
                               "ply\nformat ascii 1.0\nelement vertex 3\nproperty int128 x\n"
                               "end_header\n"),
                    4, "unsupported PLY property type");
  expect_read_error(write_text(dir, "fmt.ply", "ply\nformat binary_middle_endian 1.0\n"), 2,
                    "unsupported PLY format");
  expect_read_error(write_text(dir, "noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"), 0,
                    "end_header");
  expect_read_error(write_text(dir, "asciitrunc.ply",
                               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
                    14, "face 0: unexpected end of file");
}

TEST(MeshIo, TruncatedBinaryPlyNamesFileAndElement) {
  const std::string dir = test::temp_dir();
  const std::string good = dir + "/cube.ply";
  write_mesh(good, test::unit_cube());
  const std::string bytes = read_bytes(good);
  // Drop the last face's final index, then drop into the vertex block.
  const std::string cut_face = write_text(dir, "cut_face.ply", bytes.substr(0, bytes.size() - 2));
  expect_read_error(cut_face, 0, "face 11: unexpected end of file");
  const std::string cut_vertex =
      write_text(dir, "cut_vertex.ply", bytes.substr(0, bytes.size() - 12 * 13 - 2 * 24 - 4));
  expect_read_error(cut_vertex, 0, "vertex 5: unexpected end of file");
  // Out-of-range index in binary data.
  std::string bad = bytes;
  const std::int32_t huge = 8;
  std::memcpy(&bad[bad.size() - 4], &huge, 4);
  expect_read_error(write_text(dir, "bad_index.ply", bad), 0, "face 11: vertex index 8");
}

TEST(MeshIo, ObjFaceSyntaxNegativeIndicesQuadsAndNormals) {
  const std::string dir = test::temp_dir();
  // A unit square as one quad, using v/vt/vn and relative indices; one shared normal.
  const std::string path = write_text(dir, "quad.obj",
                                      "# comment\no square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ns off\n"
                                      "f -4/1/-1 -3/2/-1 -2/3/-1 -1/4/-1\n");
  const TriMesh m = read_mesh(path);
  ASSERT_EQ(m.num_faces(), 2);
  ASSERT_EQ(m.num_vertices(), 4);
  EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 2, 3));
  ASSERT_EQ(m.N.rows(), 4);
  for (int v = 0; v < 4; ++v) EXPECT_EQ(m.N.row(v), Eigen::RowVector3d(0, 0, 1));

  // Same vertex used with two different normals: no per-vertex normals.
  const TriMesh flat =
      read_mesh(write_text(dir, "flat.obj",
                           "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nvn 1 0 0\n"
                           "f 1//1 2//1 3//1\nf 1//2 3//2 4//2\n"));
  EXPECT_EQ(flat.num_faces(), 2);
  EXPECT_EQ(flat.N.rows(), 0);
  // "v/vt" form and an unreferenced vertex, which is kept.
  const TriMesh vt = read_mesh(
      write_text(dir, "vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 9 9 9\nvt 0 0\nf 1/1 2/1 3/1\n"));
  EXPECT_EQ(vt.num_vertices(), 4);
  EXPECT_EQ(vt.N.rows(), 0);
  EXPECT_EQ(vt.V(3, 0), 9.0);
}

TEST(MeshIo, OffVariantsAndComments) {
  const std::string dir = test::temp_dir();
  const TriMesh m = read_mesh(write_text(dir, "c.off",
                                         "# leading comment\nCOFF\n# counts\n4 1 0\n"
                                         "0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
                                         "1 1 0 0 0 255 255\n0 1 0 9 9 9 255\n"
                                         "\n4 0 1 2 3 255 0 0\n"));
  EXPECT_EQ(m.num_faces(), 2);
  EXPECT_EQ(m.V(2, 1), 1.0);
  const TriMesh n = read_mesh(write_text(dir, "n.off",
                                         "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n"
                                         "3 0 1 2\n"));
  ASSERT_EQ(n.N.rows(), 3);
  EXPECT_EQ(n.N(1, 2), 1.0);
}

TEST(MeshIo, PlyAsciiWithExtraPropertiesAndElements) {
  const std::string dir = test::temp_dir();
  // Property order z y x, extra vertex properties, an edge element before the faces, ushort
  // list counts, uint indices and an extra face property.
  const std::string path = write_text(
      dir, "extra.ply",
      "ply\r\nformat ascii 1.0\r\ncomment hello\r\nelement vertex 4\r\nproperty uchar red\r\n"
      "property float z\r\nproperty double y\r\nproperty float x\r\n"
      "property list uchar int tags\r\nelement edge 2\r\nproperty int vertex1\r\n"
      "property int vertex2\r\nelement face 1\r\nproperty list ushort uint vertex_indices\r\n"
      "property uchar flags\r\nend_header\r\n"
      "1 0 0 0 0\r\n2 0 0 1 2 7 7\r\n3 0 1 1 0\r\n4 0.5 1 0 1 8\r\n0 1\r\n1 2\r\n4 0 1 2 3 9\r\n");
  const TriMesh m = read_mesh(path);
  ASSERT_EQ(m.num_vertices(), 4);
  ASSERT_EQ(m.num_faces(), 2);
  EXPECT_EQ(m.V.row(1), Eigen::RowVector3d(1, 0, 0));
  EXPECT_EQ(m.V.row(3), Eigen::RowVector3d(0, 1, 0.5));
  EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(m.N.rows(), 0);
}

template <typename T>
void put_be(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  std::reverse(b, b + sizeof(T));  // the tests run on little-endian hosts
  out.append(b, sizeof(T));
}

TEST(MeshIo, PlyBinaryBigEndianFloatAndSkippedLists) {
  const std::string dir = test::temp_dir();
  std::string data =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
      "element face 1\nproperty list uchar float texcoord\n"
      "property list uint short vertex_indices\nend_header\n";
  const float xyz[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 2.5f, 0}};
  for (const auto& p : xyz) {
    for (float c : p) put_be(data, c);
    for (float c : {0.f, 0.f, 1.f}) put_be(data, c);
  }
  data += char(2);
  put_be(data, 0.25f);
  put_be(data, 0.75f);
  put_be(data, std::uint32_t(3));
  for (std::int16_t i : {2, 1, 0}) put_be(data, i);
  const TriMesh m = read_mesh(write_text(dir, "be.ply", data));
  ASSERT_EQ(m.num_faces(), 1);
  EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(2, 1, 0));
  EXPECT_EQ(m.V(2, 1), 2.5);
  ASSERT_EQ(m.N.rows(), 3);
  EXPECT_EQ(m.N(0, 2), 1.0);
}

TEST(MeshIo, RoundTripAllFormatsOnRealMesh) {
  const std::string dir = test::temp_dir();
  const TriMesh bunny = read_mesh(test::shared_data("base/bunny_igl_7k.off"));
  struct Case {
    const char* name;
    WriteOptions options;
  };
  WriteOptions exact;
  exact.precision = 17;
  WriteOptions ascii17 = exact;
  ascii17.binary = false;
  WriteOptions shortest;
  shortest.precision = 0;
  shortest.binary = false;
  for (const auto& [name, options] :
       {Case{"a.obj", exact}, Case{"a.off", exact}, Case{"a.ply", exact}, Case{"b.ply", ascii17},
        Case{"s.obj", shortest}, Case{"d.ply", WriteOptions{}}}) {
    SCOPED_TRACE(name);
    const std::string path = dir + "/" + name;
    write_mesh(path, bunny, options);
    const TriMesh back = read_mesh(path);
    expect_same_mesh(bunny, back);
    EXPECT_EQ(back.N.rows(), 0);
  }
  // Default precision (9 digits): each coordinate is the nearest 9-digit decimal.
  for (const char* name : {"c.obj", "c.off", "c.ply"}) {
    SCOPED_TRACE(name);
    const std::string path = dir + "/" + name;
    WriteOptions text;
    text.binary = false;
    write_mesh(path, bunny, text);
    const TriMesh back = read_mesh(path);
    ASSERT_EQ(back.V.rows(), bunny.V.rows());
    EXPECT_TRUE(back.F == bunny.F);
    for (Eigen::Index i = 0; i < bunny.V.size(); ++i) {
      const double v = bunny.V.data()[i];
      char buf[64];
      *std::to_chars(buf, buf + 63, v, std::chars_format::scientific, 8).ptr = '\0';
      EXPECT_EQ(back.V.data()[i], std::strtod(buf, nullptr));
    }
  }
}

TEST(MeshIo, RoundTripNormals) {
  const std::string dir = test::temp_dir();
  TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  WriteOptions options;
  options.write_normals = true;
  options.precision = 17;
  // Computed normals (mesh.N empty) are written, then the file's normals are read back.
  for (const char* name : {"t.obj", "t.off", "t.ply"}) {
    SCOPED_TRACE(name);
    write_mesh(dir + "/" + name, torus, options);
    const TriMesh back = read_mesh(dir + "/" + name);
    expect_same_mesh(torus, back);
    ASSERT_EQ(back.N.rows(), torus.V.rows());
    EXPECT_NEAR(back.N.row(0).norm(), 1.0, 1e-12);
    torus.N = back.N;  // explicit normals are written verbatim the second time
    write_mesh(dir + "/2" + name, torus, options);
    EXPECT_TRUE(read_mesh(dir + "/2" + name).N == torus.N);
    torus.N.resize(0, 3);
  }
  const std::string obj = read_bytes(dir + "/t.obj");
  EXPECT_NE(obj.find("\nf 1//1 "), std::string::npos);
  EXPECT_NE(obj.find("\nvn "), std::string::npos);
}

TEST(MeshIo, OutputIsDeterministicAndWellFormed) {
  const std::string dir = test::temp_dir();
  const TriMesh cube = test::unit_cube();
  for (const char* name : {"x.obj", "x.off", "x.ply"}) {
    write_mesh(dir + "/1" + name, cube);
    write_mesh(dir + "/2" + name, cube);
    EXPECT_EQ(read_bytes(dir + "/1" + name), read_bytes(dir + "/2" + name)) << name;
  }
  const std::string obj = read_bytes(dir + "/1x.obj");
  EXPECT_EQ(obj.rfind("v 0 0 0\nv 1 0 0\n", 0), 0u) << obj.substr(0, 40);
  EXPECT_NE(obj.find("\nf 1 3 2\n"), std::string::npos);
  EXPECT_EQ(read_bytes(dir + "/1x.off").rfind("OFF\n8 12 0\n0 0 0\n", 0), 0u);
  const std::string ply = read_bytes(dir + "/1x.ply");
  EXPECT_EQ(ply.rfind("ply\nformat binary_little_endian 1.0\nelement vertex 8\n"
                      "property double x\nproperty double y\nproperty double z\n"
                      "element face 12\nproperty list uchar int vertex_indices\nend_header\n",
                      0),
            0u);
  EXPECT_EQ(ply.size(), ply.find("end_header\n") + 11 + 8 * 24 + 12 * 13);
}

std::vector<std::string> directory_listing(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(MeshIo, FailedWriteLeavesExistingFileUntouched) {
  const std::string dir = test::temp_dir();
  const std::string path = dir + "/keep.obj";
  write_mesh(path, test::unit_cube());
  const std::string before = read_bytes(path);
  TriMesh bad = test::unit_cube();
  bad.V(5, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_mesh(path, bad), InvalidInput);
  TriMesh bad_index = test::unit_cube();
  bad_index.F(3, 2) = 8;
  EXPECT_THROW(write_mesh(path, bad_index), InvalidInput);
  EXPECT_THROW(write_mesh(dir + "/keep.stl", test::unit_cube()), InvalidInput);
  EXPECT_EQ(read_bytes(path), before);
  EXPECT_EQ(directory_listing(dir), std::vector<std::string>{"keep.obj"});
  // An overwrite that succeeds replaces the content and leaves no temporary file either.
  write_mesh(path, test::torus(1, 0.25, 6, 4));
  EXPECT_NE(read_bytes(path), before);
  EXPECT_EQ(directory_listing(dir), std::vector<std::string>{"keep.obj"});
}

TEST(MeshIo, UnwritableDirectoryThrowsErrorNamingFile) {
  const std::string path = test::temp_dir() + "/no/such/dir/out.ply";
  try {
    write_mesh(path, test::unit_cube());
    ADD_FAILURE() << "no exception";
  } catch (const InvalidInput& e) {
    ADD_FAILURE() << "I/O failure reported as InvalidInput: " << e.what();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(MeshIo, MillionFaceGridRoundTripsInBinaryPlyAndObj) {
  const std::string dir = test::temp_dir();
  const TriMesh grid = test::plane_grid(3.0, 2.0, 708, 708);  // 1,002,528 faces
  ASSERT_GT(grid.num_faces(), 1000000);
  write_mesh(dir + "/grid.ply", grid);
  expect_same_mesh(grid, read_mesh(dir + "/grid.ply"));
  WriteOptions exact;
  exact.precision = 17;
  write_mesh(dir + "/grid.obj", grid, exact);
  expect_same_mesh(grid, read_mesh(dir + "/grid.obj"));
}

}  // namespace
}  // namespace mq
