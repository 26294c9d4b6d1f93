// Progress on stderr: a bar with the estimated time remaining when stderr is a terminal, plain
// periodic lines otherwise (logs, CI), nothing when quiet. For programs that show it themselves
// (the Blender add-on), machine lines at most every 0.25 s and at each stage's end:
//   progress STAGE FRACTION ELAPSED_S REMAINING_S
// with FRACTION in [0, 1] and REMAINING_S the stage's estimate, -1 while there is none.
#pragma once

#include <chrono>
#include <string>

#include "core/common/progress.h"

namespace mq::cli {

class ConsoleProgress final : public ProgressSink {
 public:
  explicit ConsoleProgress(bool quiet, bool machine = false);
  ~ConsoleProgress() override;
  void update(const std::string& stage, double done, double total) override;
  void finish() override;

 private:
  using Clock = std::chrono::steady_clock;
  bool quiet_;
  bool terminal_;
  bool machine_;
  bool line_open_ = false;
  Clock::time_point start_;
  Clock::time_point last_print_;
  std::string stage_;
  Clock::time_point stage_start_;
  double last_fraction_ = -1;
};

// "1:05" / "1:02:03" for a duration in seconds.
std::string format_duration(double seconds);

}  // namespace mq::cli
