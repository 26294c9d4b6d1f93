// surface and plane check the structure of what they made (issue 23: no silent wrong result): a
// result that lost the swatch's links, density or thread lengths is written, and said so on
// stderr and in --stats; one that kept them is not flagged.
#include <gtest/gtest.h>

#include <string>

#include "tests/cli/cli_support.h"
#include "tests/test_support.h"

namespace mq {
namespace {

class CliStructureCheck : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temp_dir(); }
  std::string dir_;
};

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST_F(CliStructureCheck, ChainMailByPatchesOnASphereIsFlaggedTheGlobalLayoutIsNot) {
  // A sheet of 2 x 4 rings is smaller than the local patches' overlap: they place it in clumps
  // with gaps between (measured: 16% of interior rings with their 4 links, 30% of the swatch's
  // density); the global layout keeps 86% and 87%.
  write_obj(dir_ + "/sphere.obj", test::uv_sphere(1.0, 16, 8));
  ASSERT_EQ(meshquilt(dir_, "swatch chainmail --rows 2 --cols 4 -o sw.obj --quiet").status, 0);
  const std::string job = "surface --base sphere.obj --swatch sw.obj --scale 0.3 -o o.ply";
  const CliRun patches = meshquilt(dir_, job + " --method patches --stats p.json");
  ASSERT_EQ(patches.status, 0) << patches.err;
  EXPECT_EQ(count(patches.err, "meshquilt surface: warning: "), 2) << patches.err;
  EXPECT_NE(patches.err.find("of interior rings keep their swatch's links, under 75.0%"),
            std::string::npos)
      << patches.err;
  EXPECT_NE(patches.err.find("as dense as the swatch's, under 70.0% (gaps); --method global"),
            std::string::npos)
      << patches.err;
  const std::string p = slurp(dir_ + "/p.json");
  EXPECT_EQ(json_value(p, "passed"), "false");
  EXPECT_EQ(json_value(p, "measure"), "\"links\"");
  EXPECT_LT(std::stod(json_value(p, "value")), 0.5);
  // Without --stats and with --quiet the warning is still given.
  const CliRun quiet = meshquilt(dir_, job + " --method patches --quiet");
  ASSERT_EQ(quiet.status, 0) << quiet.err;
  EXPECT_EQ(count(quiet.err, "warning: "), 2) << quiet.err;
  EXPECT_TRUE(quiet.out.empty()) << quiet.out;

  const CliRun global = meshquilt(dir_, job + " --method global --stats g.json");
  ASSERT_EQ(global.status, 0) << global.err;
  EXPECT_EQ(global.err.find("warning"), std::string::npos) << global.err;
  EXPECT_NE(global.out.find("structure kept:"), std::string::npos) << global.out;
  const std::string g = slurp(dir_ + "/g.json");
  EXPECT_EQ(json_value(g, "passed"), "true");
  EXPECT_GE(std::stod(json_value(g, "share_with_swatch_links")), 0.75);
}

TEST_F(CliStructureCheck, AutoLaysAnOddRowSheetOutWholeAndSaysWhenNoLatticeRepeats) {
  // The 3 x 3 sheet at the generator's detail went to the patches (its last row's rings reach
  // past their centres: a shifted row was judged missing) and lost its links; it is a lattice.
  write_obj(dir_ + "/sphere.obj", test::uv_sphere(1.0, 16, 8));
  ASSERT_EQ(meshquilt(dir_, "swatch chainmail --rows 3 --cols 3 -o s33.obj --quiet").status, 0);
  const std::string job = "surface --base sphere.obj -o o.ply --quiet";
  const CliRun odd = meshquilt(dir_, job + " --swatch s33.obj --scale 0.3 --stats o.json");
  ASSERT_EQ(odd.status, 0) << odd.err;
  EXPECT_EQ(odd.err.find("warning"), std::string::npos) << odd.err;
  const std::string o = slurp(dir_ + "/o.json");
  EXPECT_EQ(json_value(o, "method"), "\"global\"");
  EXPECT_GE(std::stod(json_value(o, "share_with_swatch_links")), 0.75);
  // A 2 x 2 sheet shows no period twice: no layout can repeat it (the patches: 21.5% linked,
  // 25% of its density at 0.2), and the hint says so rather than sending the user to --method
  // global.
  ASSERT_EQ(meshquilt(dir_, "swatch chainmail --rows 2 --cols 2 -o s22.obj --quiet").status, 0);
  const CliRun small = meshquilt(dir_, job + " --swatch s22.obj --scale 0.2");
  ASSERT_EQ(small.status, 0) << small.err;
  EXPECT_GE(count(small.err, "warning: "), 1) << small.err;
  EXPECT_EQ(count(small.err, "warning: "), count(small.err, "no lattice repeats in the swatch"))
      << small.err;
}

TEST_F(CliStructureCheck, WeaveByPatchesOnAPlaneIsFlaggedForThreadsCutAtSeams) {
  // Every thread of the local patches' weave is one swatch thread long (cut where patches
  // meet); the global layout's run 3.2 swatch threads (median) on the same 2 x 2 square.
  write_obj(dir_ + "/flat.obj", test::plane_grid(2.0, 2.0, 20, 20));
  ASSERT_EQ(meshquilt(dir_, "swatch weave -o sw.obj --quiet").status, 0);
  const std::string job = "surface --base flat.obj --swatch sw.obj --scale 0.2 -o o.ply --quiet";
  const CliRun patches = meshquilt(dir_, job + " --method patches --stats p.json");
  ASSERT_EQ(patches.status, 0) << patches.err;
  EXPECT_EQ(count(patches.err, "warning: "), 1) << patches.err;
  EXPECT_NE(patches.err.find("the median thread runs 1.00 swatch threads, under 1.5"),
            std::string::npos)
      << patches.err;
  EXPECT_EQ(json_value(slurp(dir_ + "/p.json"), "measure"), "\"long_length\"");
  const CliRun global = meshquilt(dir_, job + " --method global --stats g.json");
  ASSERT_EQ(global.status, 0) << global.err;
  EXPECT_EQ(global.err.find("warning"), std::string::npos) << global.err;
  const std::string g = slurp(dir_ + "/g.json");
  EXPECT_EQ(json_value(g, "passed"), "true");
  EXPECT_GE(std::stod(json_value(g, "long_length_ratio")), 1.5);
}

TEST_F(CliStructureCheck, PlaneFromASwatchOfTwoThreadsEachWayIsFlagged) {
  // Two threads each way leave the patches nothing to carry a thread on across their overlaps:
  // every thread is cut where patches meet (measured: 0.98 swatch threads; 1.00 before a thread
  // whose stitch is refused entered in part); the 6 x 6 sample runs 2.09 swatch threads on the
  // same layer.
  ASSERT_EQ(meshquilt(dir_, "swatch weave --rows 2 --cols 2 -o small.obj --quiet").status, 0);
  ASSERT_EQ(meshquilt(dir_, "swatch weave -o sample.obj --quiet").status, 0);
  const std::string job = "plane --size 12 12 -o o.ply --quiet --stats s.json --swatch ";
  const CliRun small = meshquilt(dir_, job + "small.obj");
  ASSERT_EQ(small.status, 0) << small.err;
  const std::string warning = "meshquilt plane: warning: the median thread runs ";
  const size_t at = small.err.find(warning);
  ASSERT_NE(at, std::string::npos) << small.err;
  EXPECT_LT(std::stod(small.err.substr(at + warning.size())), 1.05) << small.err;
  EXPECT_EQ(json_value(slurp(dir_ + "/s.json"), "passed"), "false");
  const CliRun sample = meshquilt(dir_, job + "sample.obj");
  ASSERT_EQ(sample.status, 0) << sample.err;
  EXPECT_TRUE(sample.err.empty()) << sample.err;
  EXPECT_EQ(json_value(slurp(dir_ + "/s.json"), "passed"), "true");
}

}  // namespace
}  // namespace mq
