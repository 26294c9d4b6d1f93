#include "cli/run_context.h"

#include <tbb/info.h>

#include <filesystem>

#include "core/errors.h"

namespace mq::cli {

Device parse_device(const std::string& name) {
  if (name == "auto") return Device::Auto;
  if (name == "cpu") return Device::Cpu;
  if (name == "opencl") return Device::OpenCL;
  throw UsageError("--device expects auto, cpu or opencl, got '" + name + "'");
}

void add_run_options(CommandLine& cl) {
  cl.flag("quiet", "print nothing but errors (no progress, no summary)");
  cl.option("stats", "FILE.json", "write counts and per-stage timings as JSON");
  cl.option("threads", "N", "worker threads (0 = all cores)", "0");
}

void check_output_directory(const std::string& path) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  MQ_CHECK(dir.empty() || std::filesystem::is_directory(dir, ec), InvalidInput, path,
           ": the directory '", dir.string(), "' does not exist");
}

RunContext::RunContext(const CommandLine& cl)
    : quiet_(cl.has("quiet")),
      stats_path_(cl.get("stats")),
      threads_(static_cast<int>(cl.get_int("threads", 0, 1024))),
      progress_(quiet_) {
  if (!stats_path_.empty()) check_output_directory(stats_path_);
  if (threads_ > 0)
    control_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     static_cast<size_t>(threads_));
  else
    threads_ = tbb::info::default_concurrency();
}

}  // namespace mq::cli
