// The OpenCL platform, device, context and queue used by the kernels, plus their program cache.
#pragma once

#include <CL/cl.h>

#include <memory>
#include <string>

#include "host/opencl_handles.h"
#include "host/program_cache.h"

namespace mq::cl {

// Device choice. Empty fields fall back to the environment variables MESHQUILT_CL_PLATFORM and
// MESHQUILT_CL_DEVICE; when both are empty too, the default is PoCL's CPU device (the first
// platform whose name contains "Portable Computing Language"), else the first CPU device, else
// the first device. Matching is by case-insensitive substring of the platform / device name.
struct RuntimeOptions {
  std::string platform;
  std::string device;
};

// Owns the chosen platform/device, one context and one in-order command queue. Not copyable;
// share it through std::shared_ptr. Not thread-safe: use one Runtime per thread.
class Runtime {
 public:
  // Throws DeviceError when no platform exists, no device matches the requested substrings
  // (the message lists the available devices), or context/queue creation fails.
  explicit Runtime(const RuntimeOptions& options = {});
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  // True when at least one OpenCL platform is installed. Never throws.
  static bool available() noexcept;

  cl_platform_id platform() const { return platform_; }
  cl_device_id device() const { return device_; }
  cl_context context() const { return context_.get(); }
  cl_command_queue queue() const { return queue_.get(); }
  const std::string& platform_name() const { return platform_name_; }
  const std::string& device_name() const { return device_name_; }
  // Whether the device supports double precision (cl_khr_fp64).
  bool has_fp64() const { return has_fp64_; }

  // Built programs for this device, keyed by source hash and options.
  ProgramCache& programs() { return *programs_; }

 private:
  cl_platform_id platform_ = nullptr;
  cl_device_id device_ = nullptr;
  std::string platform_name_, device_name_;
  bool has_fp64_ = false;
  Context context_;
  CommandQueue queue_;
  // Declared last: programs are released before the context.
  std::unique_ptr<ProgramCache> programs_;
};

}  // namespace mq::cl
