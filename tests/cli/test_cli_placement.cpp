// surface checks what it made (issue 23): the placement block of --stats, a coverage that is a
// true fraction, and --min-coverage failing a result that leaves the base bare.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "tests/cli/cli_support.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TriMesh flipped(TriMesh m) {
  for (int f = 0; f < m.num_faces(); ++f) std::swap(m.F(f, 1), m.F(f, 2));
  return m;
}

class CliPlacement : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir();
    ASSERT_EQ(
        meshquilt(dir_, "swatch chainmail --rows 2 --cols 2 --detail 8 -o sw.obj --quiet").status,
        0);
  }
  std::string dir_;
};

TEST_F(CliPlacement, StatsCarryTheCheckAndATrueCoverage) {
  // An open tube (open ends, as the quadruped's legs): outward as given, and inside out.
  const TriMesh tube = test::open_cylinder(1.0, 2.0, 32, 8);
  write_obj(dir_ + "/tube.obj", tube);
  write_obj(dir_ + "/inside_out.obj", flipped(tube));
  const std::string job = "surface --swatch sw.obj --scale 0.12 -o o.obj --stats s.json";
  const CliRun a = meshquilt(dir_, job + " --base tube.obj");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_NE(a.out.find("placement: 0.00% of vertices under the base"), std::string::npos) << a.out;
  std::string stats = slurp(dir_ + "/s.json");
  EXPECT_NE(stats.find("\"placement\": {"), std::string::npos);
  EXPECT_EQ(json_value(stats, "shell_map"), "\"whole base\"");
  EXPECT_EQ(std::stod(json_value(stats, "below_base")), 0.0);
  EXPECT_GE(std::stod(json_value(stats, "lowest_height")), -0.01);
  EXPECT_GT(std::stoll(json_value(stats, "vertices")), 0);
  const double coverage = std::stod(json_value(stats, "coverage"));
  EXPECT_GE(coverage, 0.9);
  EXPECT_LE(coverage, 1.0);
  EXPECT_EQ(std::stod(json_value(stats, "swatch_coverage")), 1.0);
  EXPECT_EQ(json_value(stats, "min_coverage"), "0.9");
  // Inside out: turned outward (the winding number sees through the open ends).
  const CliRun b = meshquilt(dir_, job + " --base inside_out.obj");
  ASSERT_EQ(b.status, 0) << b.err;
  stats = slurp(dir_ + "/s.json");
  EXPECT_EQ(json_value(stats, "flipped_components"), "1");
  EXPECT_NEAR(std::stod(json_value(stats, "coverage")), coverage, 0.02);
  // Kept inside out, the texture grows inside the tube: the coverage is still a fraction.
  const CliRun c =
      meshquilt(dir_, job + " --base inside_out.obj --keep-orientation --min-coverage 0");
  ASSERT_EQ(c.status, 0) << c.err;
  stats = slurp(dir_ + "/s.json");
  EXPECT_EQ(json_value(stats, "flipped_components"), "0");
  EXPECT_GE(std::stod(json_value(stats, "coverage")), 0.0);
  EXPECT_LE(std::stod(json_value(stats, "coverage")), 1.0);
  EXPECT_EQ(std::stod(json_value(stats, "below_base")), 0.0);
}

TEST_F(CliPlacement, ABareBaseFailsWithItsCauseAndWritesNothing) {
  // A 4 x 4 sheet facing up and, 0.02 over its right half, a 2 x 4 sheet facing down: the rings
  // between them (the shell is 0.16 high) lie inside the other sheet's side and are removed.
  TriMesh a = test::plane_grid(4, 4, 8, 8);
  TriMesh b = flipped(test::plane_grid(2, 4, 4, 8));
  b.V.col(0).array() += 2;
  b.V.col(2).array() += 0.02;
  const Eigen::Index n = a.V.rows();
  a.V.conservativeResize(n + b.V.rows(), 3);
  a.V.bottomRows(b.V.rows()) = b.V;
  const Eigen::Index m = a.F.rows();
  a.F.conservativeResize(m + b.F.rows(), 3);
  a.F.bottomRows(b.F.rows()) = b.F.array() + static_cast<int>(n);
  write_obj(dir_ + "/facing.obj", a);
  const std::string job = "surface --base facing.obj --swatch sw.obj --scale 0.08 -o o.obj";
  const CliRun r = meshquilt(dir_, job + " --stats s.json --quiet");
  EXPECT_EQ(r.status, 1);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  const std::string line = r.err_lines()[0];
  EXPECT_NE(line.find("% of the base is covered, below 90%"), std::string::npos) << line;
  EXPECT_NE(line.find("inside the base"), std::string::npos) << line;
  EXPECT_NE(line.find("nothing written"), std::string::npos) << line;
  EXPECT_FALSE(fs::exists(dir_ + "/o.obj"));
  EXPECT_FALSE(fs::exists(dir_ + "/s.json"));
  // Accepted when asked for less; the figures say what happened.
  const CliRun ok = meshquilt(dir_, job + " --stats s.json --min-coverage 0.2 --quiet");
  ASSERT_EQ(ok.status, 0) << ok.err;
  const std::string stats = slurp(dir_ + "/s.json");
  EXPECT_GT(std::stoi(json_value(stats, "removed_below")), 0);
  EXPECT_GT(std::stod(json_value(stats, "below_base_embedded")), 0.1);
  EXPECT_EQ(std::stod(json_value(stats, "below_base")), 0.0);
  EXPECT_LT(std::stod(json_value(stats, "coverage")), 0.5);
  // A fraction is expected.
  EXPECT_EQ(meshquilt(dir_, job + " --min-coverage 1.5").status, 2);
}

}  // namespace
}  // namespace mq
