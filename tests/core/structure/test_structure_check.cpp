// The structure check's limits (core/structure/structure_check) on comparisons made up to sit
// either side of each limit (the CLI tests run it on real results).
#include <gtest/gtest.h>

#include <cmath>

#include "core/common/errors.h"
#include "core/structure/structure_check.h"

namespace mq {
namespace {

using Measure = StructureShortfall::Measure;

// Rings: `interior` of them judged against a swatch kind of 4 links, `share` with them.
StructureSummary rings(int interior, double share) {
  StructureSummary s;
  s.swatch.interior_links = 4;
  s.comparison.interior_links = 4;
  s.comparison.share_matching = share;
  KindComparison k;
  k.kind = "ring";
  k.interior_links = 4;
  k.interior_rings = interior;
  k.share = share;
  s.comparison.kinds.push_back(k);
  return s;
}

// Threads `ratio` swatch threads long (median), `interior` of their `ends` inside the surface.
StructureSummary threads(double ratio, int ends, int interior) {
  StructureSummary s;
  s.comparison.long_length_ratio = ratio;
  s.output.ends = ends;
  s.output.interior_ends = interior;
  return s;
}

TEST(StructureCheck, RingsUnderTheShareAreFlaggedOnlyWhenThereAreEnoughToJudge) {
  const std::vector<StructureShortfall> low = check_structure(rings(60, 0.5));
  ASSERT_EQ(low.size(), 1u);
  EXPECT_EQ(low[0].measure, Measure::Links);
  EXPECT_DOUBLE_EQ(low[0].value, 0.5);
  EXPECT_DOUBLE_EQ(low[0].limit, 0.75);
  EXPECT_EQ(low[0].text, "50.0% of interior rings keep their swatch's links, under 75.0%");
  EXPECT_TRUE(check_structure(rings(60, 0.75)).empty());
  // 40 interior rings (of a soup of open pieces, all but a few border rings): one more or less
  // moves the share by 2.5%; not judged.
  EXPECT_TRUE(check_structure(rings(40, 0.2)).empty());
  // A swatch without rings has no links to keep.
  StructureSummary no_rings = rings(60, 0.0);
  no_rings.swatch.interior_links = -1;
  EXPECT_TRUE(check_structure(no_rings).empty());
}

TEST(StructureCheck, DensityIsJudgedBothWaysForCompactSwatchesOnly) {
  StructureSummary c;  // a swatch without long elements
  c.output.density_cells = 100;
  c.comparison.density_ratio = 0.5;
  std::vector<StructureShortfall> s = check_structure(c);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].measure, Measure::Density);
  EXPECT_DOUBLE_EQ(s[0].limit, 0.7);
  EXPECT_NE(s[0].text.find("50.0% as dense as the swatch's, under 70.0% (gaps)"), std::string::npos)
      << s[0].text;
  c.comparison.density_ratio = 1.5;
  s = check_structure(c);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_DOUBLE_EQ(s[0].limit, 1.4);
  EXPECT_NE(s[0].text.find("over 140.0% (crowded)"), std::string::npos) << s[0].text;
  c.comparison.density_ratio = 1.0;
  EXPECT_TRUE(check_structure(c).empty());
  // Measured on 30 closed cells: not judged.
  c.output.density_cells = 30;
  c.comparison.density_ratio = 0.5;
  EXPECT_TRUE(check_structure(c).empty());
  c.output.density_cells = 100;
  // Vines with leaves: stems are spaced out by design, their leaves' density says nothing.
  c.swatch.report.long_elements = 2;
  c.comparison.density_ratio = 0.1;
  EXPECT_TRUE(check_structure(c).empty());
}

TEST(StructureCheck, ThreadsCutInsideTheSurfaceAreFlaggedNotThoseItsBorderEnds) {
  const std::vector<StructureShortfall> s = check_structure(threads(1.0, 148, 117));
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].measure, Measure::LongLength);
  EXPECT_EQ(s[0].text,
            "the median thread runs 1.00 swatch threads, under 1.5 (cut where patches meet)");
  EXPECT_TRUE(check_structure(threads(3.2, 84, 19)).empty());
  // No long elements measured.
  EXPECT_TRUE(check_structure(threads(0, 0, 0)).empty());
  // Short because the surface is: most ends on its border.
  EXPECT_TRUE(check_structure(threads(1.0, 40, 10)).empty());
}

TEST(StructureCheck, AMedianElementFarFromTheSwatchsSizeIsFlagged) {
  StructureSummary c;
  c.comparison.shape.elements = 100;
  c.comparison.shape.size_median = 0.37;  // the dragon's rings when its metric was followed
  std::vector<StructureShortfall> s = check_structure(c);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].measure, Measure::Size);
  EXPECT_EQ(s[0].text, "the median element is 0.37x the swatch's, under 0.75x");
  c.comparison.shape.size_median = 1.5;
  s = check_structure(c);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].text, "the median element is 1.50x the swatch's, over 1.33x");
  c.comparison.shape.size_median = 0.876;  // the armor's
  EXPECT_TRUE(check_structure(c).empty());
  c.comparison.shape.size_median = 0.37;
  c.comparison.shape.elements = 30;  // too few to judge
  EXPECT_TRUE(check_structure(c).empty());
}

TEST(StructureCheck, EveryShortfallInMeasureOrderWithItsName) {
  StructureSummary c = rings(100, 0.1);
  c.output.density_cells = 100;
  c.comparison.density_ratio = 0.3;
  c.comparison.long_length_ratio = 1.2;
  c.output.ends = c.output.interior_ends = 10;
  c.comparison.shape.elements = 100;
  c.comparison.shape.size_median = 2.0;
  const std::vector<StructureShortfall> s = check_structure(c);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_STREQ(structure_measure_name(s[0].measure), "links");
  EXPECT_STREQ(structure_measure_name(s[1].measure), "density");
  EXPECT_STREQ(structure_measure_name(s[2].measure), "long_length");
  EXPECT_STREQ(structure_measure_name(s[3].measure), "size");
}

TEST(StructureCheck, OptionsAreValidated) {
  StructureCheckOptions o;
  EXPECT_NO_THROW(o.validate());
  o.min_link_share = 1.5;
  EXPECT_THROW(check_structure(StructureSummary{}, o), InvalidInput);
  o = {};
  o.min_density = 0;
  EXPECT_THROW(o.validate(), InvalidInput);
  o = {};
  o.max_density = 0.9;
  EXPECT_THROW(o.validate(), InvalidInput);
  o = {};
  o.max_size = 0.9;
  EXPECT_THROW(o.validate(), InvalidInput);
  o = {};
  o.min_long_length = std::nan("");
  EXPECT_THROW(o.validate(), InvalidInput);
}

}  // namespace
}  // namespace mq
