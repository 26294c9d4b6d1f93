#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/common/stage_timer.h"

namespace mq {
namespace {

TEST(Stage, EveryStageHasItsOwnLowerCaseName) {
  std::set<std::string> names;
  for (int s = 0; s <= static_cast<int>(Stage::Writing); ++s) {
    const std::string name = stage_name(static_cast<Stage>(s));
    EXPECT_FALSE(name.empty());
    for (const char c : name) EXPECT_TRUE((c >= 'a' && c <= 'z') || c == ' ' || c == '-') << name;
    names.insert(name);
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(Stage::Writing) + 1);
  // The add-on weighs progress by these names (blender/meshquilt/engine.py).
  EXPECT_STREQ(stage_name(Stage::ShellMap), "shell map");
  EXPECT_STREQ(stage_name(Stage::StretchOptimization), "stretch optimization");
  EXPECT_STREQ(stage_name(Stage::Writing), "writing");
}

TEST(StageTimes, AccumulatesInOrderOfFirstAppearanceAndMerges) {
  StageTimes a, b;
  a.add(Stage::Matching, 1.0);
  a.add(Stage::Merging, 2.0);
  a.add(Stage::Matching, 0.5);
  b.add(Stage::Coverage, 4.0);
  b.add(Stage::Merging, 1.0);
  a.merge(b);
  const std::vector<std::pair<std::string, double>> expected = {
      {"matching", 1.5}, {"merging", 3.0}, {"coverage", 4.0}};
  EXPECT_EQ(a.stages(), expected);
  EXPECT_DOUBLE_EQ(a.total(), 8.5);
}

class Recorder final : public ProgressSink {
 public:
  void update(const std::string& stage, double done, double total) override {
    seen.emplace_back(stage, done / total);
  }
  std::vector<std::pair<std::string, double>> seen;
};

TEST(ScopedStage, ShowsTheStageStartingAndEndingAndTimesIt) {
  StageTimes times;
  Recorder progress;
  { const ScopedStage stage(times, &progress, Stage::FoldRepair); }
  { const ScopedStage stage(times, nullptr, Stage::Coverage); }  // timed, not shown
  const std::vector<std::pair<std::string, double>> shown = {{"fold repair", 0.0},
                                                             {"fold repair", 1.0}};
  EXPECT_EQ(progress.seen, shown);
  ASSERT_EQ(times.stages().size(), 2u);
  EXPECT_EQ(times.stages()[0].first, "fold repair");
  EXPECT_GE(times.stages()[0].second, 0.0);
  EXPECT_EQ(times.stages()[1].first, "coverage");
}

}  // namespace
}  // namespace mq
