// meshquilt embed (issue 25): a saved quilt placed on its base again reproduces the synthesis
// byte for byte, follows a bending base over a 24-frame sequence with the same faces in every
// frame, and refuses bad quilts, other bases and missing frames in one line, writing nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "tests/cli/cli_support.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// The tube bent about the y axis by `degrees` over its height (z in [0, 2]), as a bend deformer.
TriMesh bent(TriMesh m, double degrees) {
  if (degrees == 0) return m;
  const double theta = degrees * M_PI / 180, R = 2.0 / theta;
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double phi = theta * m.V(v, 2) / 2.0, r = R - m.V(v, 0);
    m.V(v, 0) = R - r * std::cos(phi);
    m.V(v, 2) = r * std::sin(phi);
  }
  return m;
}

class CliEmbed : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir();
    ASSERT_EQ(
        meshquilt(dir_, "swatch chainmail --rows 2 --cols 2 --detail 8 -o sw.obj --quiet").status,
        0);
    tube_ = test::open_cylinder(1.0, 2.0, 32, 8);
    write_obj(dir_ + "/tube.obj", tube_);
    const CliRun r = meshquilt(dir_,
                               "surface --base tube.obj --swatch sw.obj --scale 0.12 -o rest.ply "
                               "--save-quilt q.mqq --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
  }
  std::string dir_;
  TriMesh tube_;
};

TEST_F(CliEmbed, TheUnchangedBaseGivesTheSynthesisByteForByte) {
  const CliRun r = meshquilt(dir_, "embed --quilt q.mqq --base tube.obj -o again.ply --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir_ + "/again.ply"), slurp(dir_ + "/rest.ply"));
}

TEST_F(CliEmbed, ABendingTubeIn24FramesKeepsItsFacesAndNothingIntersects) {
  for (int k = 0; k < 24; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/bend_%02d.obj", k);
    write_obj(dir_ + name, bent(tube_, 60.0 * k / 23));
  }
  const CliRun r = meshquilt(
      dir_, "embed --quilt q.mqq --base 'bend_%02d.obj' --frames 0-23 -o 'mail_%02d.ply'");
  ASSERT_EQ(r.status, 0) << r.err;
  // Frame 0 is the rest pose: the synthesis's output.
  EXPECT_EQ(slurp(dir_ + "/mail_00.ply"), slurp(dir_ + "/rest.ply"));
  const TriMesh rest = read_mesh(dir_ + "/rest.ply");
  TriMesh previous = rest;
  const double shell_height = 0.12 * std::sqrt(2.0 * 2.0 + 2.0 * 2.0 + 2.0 * 2.0) * 0.5;
  for (int k = 1; k < 24; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/mail_%02d.ply", k);
    const TriMesh m = read_mesh(dir_ + name);
    // A mesh cache: the same faces in every frame, in the same order.
    ASSERT_EQ(m.F, read_mesh(dir_ + "/mail_01.ply").F) << name;
    EXPECT_TRUE(intersecting_face_pairs(m.V, m.F).empty()) << name;
    // Motion per frame: no more than the base's own plus the shell height.
    if (m.num_vertices() == previous.num_vertices()) {
      const double base_motion = (bent(tube_, 60.0 * k / 23).V - bent(tube_, 60.0 * (k - 1) / 23).V)
                                     .rowwise()
                                     .norm()
                                     .maxCoeff();
      EXPECT_LE((m.V - previous.V).rowwise().norm().maxCoeff(), base_motion + shell_height) << name;
    }
    previous = m;
  }
  EXPECT_NE(r.out.find("mail_23.ply"), std::string::npos) << r.out;
}

TEST_F(CliEmbed, BadQuiltsOtherBasesAndMissingFramesAreRefusedWritingNothing) {
  const std::string quilt = slurp(dir_ + "/q.mqq");
  for (int tenth = 0; tenth < 10; ++tenth) {
    spit(dir_ + "/cut.mqq", quilt.substr(0, quilt.size() * tenth / 10));
    const CliRun r = meshquilt(dir_, "embed --quilt cut.mqq --base tube.obj -o cut.ply");
    EXPECT_EQ(r.status, 1) << tenth;
    EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
    EXPECT_FALSE(fs::exists(dir_ + "/cut.ply"));
  }
  write_obj(dir_ + "/other.obj", test::open_cylinder(1.0, 2.0, 32, 9));
  CliRun r = meshquilt(dir_, "embed --quilt q.mqq --base other.obj -o other.ply");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("vertices and"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ + "/other.ply"));
  // Frames 0-2 with frame 2 missing: nothing written, not even frames 0 and 1.
  write_obj(dir_ + "/f_0.obj", tube_);
  write_obj(dir_ + "/f_1.obj", bent(tube_, 10));
  r = meshquilt(dir_, "embed --quilt q.mqq --base 'f_%d.obj' --frames 0-2 -o 'o_%d.ply'");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("f_2.obj"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ + "/o_0.ply"));
  r = meshquilt(dir_, "embed --quilt q.mqq --base 'f_.obj' --frames 0-2 -o 'o_%d.ply'");
  EXPECT_EQ(r.status, 2) << r.err;
}

TEST_F(CliEmbed, EditedQuiltsLoseElementsAndTakeMaterials) {
  CliRun r = meshquilt(dir_, "edit --quilt q.mqq -o fewer.mqq --ids 0,2-4 --remove");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("4 of "), std::string::npos) << r.out;
  r = meshquilt(dir_, "edit --quilt fewer.mqq -o orange.mqq --sphere 1 0 1 0.5 --color ff8800");
  ASSERT_EQ(r.status, 0) << r.err;
  r = meshquilt(dir_, "embed --quilt orange.mqq --base tube.obj -o edited.obj --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const TriMesh rest = read_mesh(dir_ + "/rest.ply"), edited = read_mesh(dir_ + "/edited.obj");
  std::vector<int> component;
  EXPECT_EQ(connected_components(edited.F, edited.num_vertices(), component) + 4,
            connected_components(rest.F, rest.num_vertices(), component));
  EXPECT_NE(slurp(dir_ + "/edited.mtl").find("newmtl color_ff8800\nKd 1.0000 0.2462 0.0000"),
            std::string::npos);
  // Bad edits: one line, nothing written.
  for (const std::string& bad : {std::string("--kind nothing --remove"),
                                 std::string("--ids 100000 --remove"), std::string("--remove")}) {
    r = meshquilt(dir_, "edit --quilt q.mqq -o bad.mqq " + bad);
    EXPECT_EQ(r.status, 1) << bad;
    EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
    EXPECT_FALSE(fs::exists(dir_ + "/bad.mqq")) << bad;
  }
  r = meshquilt(dir_, "edit --quilt q.mqq -o bad.mqq --remove --material x");
  EXPECT_EQ(r.status, 2) << r.err;
}

}  // namespace
}  // namespace mq
