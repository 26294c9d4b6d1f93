// Built OpenCL programs, keyed by (source text hash, build options), so that each kernel
// source is compiled once per Runtime.
#pragma once

#include <CL/cl.h>

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "host/opencl_handles.h"

namespace mq::cl {

class ProgramCache {
 public:
  // Programs are built for `device` in `context`; both must outlive the cache.
  ProgramCache(cl_context context, cl_device_id device) : context_(context), device_(device) {}

  // The program built from `source` with `options`, compiling it on first use. The handle stays
  // owned by the cache and valid for its lifetime. Throws DeviceError on any OpenCL failure; a
  // compile error's message carries the build log.
  cl_program get(const std::string& source, const std::string& options = "");

  // Number of distinct programs built so far.
  std::size_t size() const { return num_programs_; }

 private:
  struct Entry {
    std::string source;  // to tell hash collisions apart
    Program program;
  };
  cl_context context_;
  cl_device_id device_;
  // Programs whose sources share a hash live side by side in one bucket.
  std::map<std::pair<std::size_t, std::string>, std::vector<Entry>> entries_;
  std::size_t num_programs_ = 0;
};

}  // namespace mq::cl
