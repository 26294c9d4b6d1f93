#include "host/program_cache.h"

#include <functional>
#include <vector>

#include "core/common/errors.h"
#include "host/opencl_check.h"

namespace mq::cl {

namespace {

std::string build_log(cl_program program, cl_device_id device) {
  std::size_t size = 0;
  if (clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size) != CL_SUCCESS)
    return "(no build log)";
  std::vector<char> log(size + 1, '\0');
  if (clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr) !=
      CL_SUCCESS)
    return "(no build log)";
  // One line for the CLI: newlines become " | ".
  std::string line;
  for (const char* c = log.data(); *c; ++c) {
    if (*c == '\n') {
      if (!line.empty() && line.back() != ' ') line += " | ";
    } else {
      line += *c;
    }
  }
  return line;
}

}  // namespace

cl_program ProgramCache::get(const std::string& source, const std::string& options) {
  const auto key = std::make_pair(std::hash<std::string>{}(source), options);
  std::vector<Entry>& bucket = entries_[key];
  for (const Entry& e : bucket)
    if (e.source == source) return e.program.get();

  cl_int err = CL_SUCCESS;
  const char* text = source.c_str();
  const std::size_t length = source.size();
  Program program(clCreateProgramWithSource(context_, 1, &text, &length, &err));
  MQ_CL_CHECK(err);
  err = clBuildProgram(program.get(), 1, &device_, options.c_str(), nullptr, nullptr);
  if (err == CL_BUILD_PROGRAM_FAILURE || err == CL_INVALID_BUILD_OPTIONS) {
    MQ_THROW(DeviceError, "OpenCL program build failed with ", error_name(err), " (options \"",
             options, "\"): ", build_log(program.get(), device_));
  }
  MQ_CL_CHECK(err);
  bucket.push_back(Entry{source, std::move(program)});
  ++num_programs_;
  return bucket.back().program.get();
}

}  // namespace mq::cl
