// Progress reporting from long-running algorithms to whatever shows it (the CLI's bar).
// Core code never prints; it calls a ProgressSink if one is given.
#pragma once

#include <string>

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

// Null-safe forwarding helper.
inline void report_progress(ProgressSink* sink, const std::string& stage, double done,
                            double total) {
  if (sink) sink->update(stage, done, total);
}

}  // namespace mq
