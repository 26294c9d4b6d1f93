// Wall-clock timing of the pipeline's stages (core/common/stage.h), accumulated over
// iterations, for --stats.
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "core/common/progress.h"
#include "core/common/stage.h"

namespace mq {

class StageTimes {
 public:
  // Adds seconds to a stage, keeping stages in order of first appearance.
  void add(Stage stage, double seconds) { add_named(stage_name(stage), seconds); }
  // Adds every stage of `other`, in its order.
  void merge(const StageTimes& other) {
    for (const auto& [name, seconds] : other.stages_) add_named(name, seconds);
  }
  // (name, seconds) per stage, in order of first appearance.
  const std::vector<std::pair<std::string, double>>& stages() const { return stages_; }
  double total() const {
    double t = 0;
    for (const auto& s : stages_) t += s.second;
    return t;
  }

 private:
  void add_named(const std::string& name, double seconds) {
    for (auto& [known, total] : stages_)
      if (known == name) {
        total += seconds;
        return;
      }
    stages_.emplace_back(name, seconds);
  }
  std::vector<std::pair<std::string, double>> stages_;
};

// Adds the lifetime of the scope to a stage of a StageTimes.
class ScopedStageTimer {
 public:
  ScopedStageTimer(StageTimes& times, Stage stage)
      : times_(times), stage_(stage), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStageTimer() {
    times_.add(stage_,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  }
  ScopedStageTimer(const ScopedStageTimer&) = delete;
  ScopedStageTimer& operator=(const ScopedStageTimer&) = delete;

 private:
  StageTimes& times_;
  Stage stage_;
  std::chrono::steady_clock::time_point start_;
};

// A stage both timed and shown: its start and end reported to `progress` (null: not shown), its
// lifetime added to `times`.
class ScopedStage {
 public:
  ScopedStage(StageTimes& times, ProgressSink* progress, Stage stage)
      : timer_(times, stage), shown_(progress, stage) {}

 private:
  ScopedStageTimer timer_;
  ScopedStageProgress shown_;
};

}  // namespace mq
