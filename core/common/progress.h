// Progress reporting from long-running algorithms to whatever shows it (the CLI's bar).
// Core code never prints; it calls a ProgressSink if one is given.
#pragma once

#include <string>

#include "core/common/stage.h"

namespace mq {

class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  // Work in `stage` has advanced to `done` of `total` units (total > 0). Called from the thread
  // driving the algorithm, never concurrently.
  virtual void update(const std::string& stage, double done, double total) = 0;
  // The run is over (successfully or not); a bar clears its line.
  virtual void finish() {}
};

// Null-safe forwarding helper: the sink sees the stage's name.
inline void report_progress(ProgressSink* sink, Stage stage, double done, double total) {
  if (sink) sink->update(stage_name(stage), done, total);
}

// A stage without finer progress: reported at 0 when the scope starts and done when it ends,
// so that whatever shows progress names every stage of a run (the shell map, the stretch
// optimisation, ...), not only those with many units of work.
class ScopedStageProgress {
 public:
  ScopedStageProgress(ProgressSink* sink, Stage stage) : sink_(sink), stage_(stage) {
    report_progress(sink_, stage_, 0, 1);
  }
  ~ScopedStageProgress() { report_progress(sink_, stage_, 1, 1); }
  ScopedStageProgress(const ScopedStageProgress&) = delete;
  ScopedStageProgress& operator=(const ScopedStageProgress&) = delete;

 private:
  ProgressSink* sink_;
  Stage stage_;
};

}  // namespace mq
