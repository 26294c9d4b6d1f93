// Options every synthesis command shares: --quiet, --stats FILE.json, --threads N, --device.
#pragma once

#include <tbb/global_control.h>

#include <memory>
#include <string>

#include "cli/command_line.h"
#include "cli/console_progress.h"
#include "host/device.h"

namespace mq::cli {

// The --device choice ("auto", "cpu" or "opencl"); throws UsageError otherwise.
Device parse_device(const std::string& name);

// Declares the shared options on a command line.
void add_run_options(CommandLine& cl);

// Throws InvalidInput naming `path` when the directory it would be written to does not exist,
// so that a run fails before its work rather than after it (leaving nothing half done).
void check_output_directory(const std::string& path);

// Applies the shared options for the lifetime of the object: thread limit and progress sink.
class RunContext {
 public:
  // Throws InvalidInput when the --stats file's directory does not exist.
  explicit RunContext(const CommandLine& cl);
  ProgressSink* progress() { return &progress_; }
  bool quiet() const { return quiet_; }
  const std::string& stats_path() const { return stats_path_; }
  int threads() const { return threads_; }

 private:
  bool quiet_;
  std::string stats_path_;
  int threads_;
  std::unique_ptr<tbb::global_control> control_;
  ConsoleProgress progress_;
};

}  // namespace mq::cli
