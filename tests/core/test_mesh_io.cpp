#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "core/errors.h"
#include "core/mesh_io.h"
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

}  // namespace
}  // namespace mq
