// Wall-clock timing of named pipeline stages, accumulated over iterations, for --stats.
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace mq {

class StageTimes {
 public:
  // Adds seconds to a stage, keeping stages in order of first appearance.
  void add(const std::string& stage, double seconds) {
    for (auto& [name, total] : stages_)
      if (name == stage) {
        total += seconds;
        return;
      }
    stages_.emplace_back(stage, seconds);
  }
  const std::vector<std::pair<std::string, double>>& stages() const { return stages_; }
  double total() const {
    double t = 0;
    for (const auto& s : stages_) t += s.second;
    return t;
  }

 private:
  std::vector<std::pair<std::string, double>> stages_;
};

// Adds the lifetime of the scope to a stage of a StageTimes.
class ScopedStageTimer {
 public:
  ScopedStageTimer(StageTimes& times, std::string stage)
      : times_(times), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStageTimer() {
    times_.add(stage_,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  }
  ScopedStageTimer(const ScopedStageTimer&) = delete;
  ScopedStageTimer& operator=(const ScopedStageTimer&) = delete;

 private:
  StageTimes& times_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace mq
