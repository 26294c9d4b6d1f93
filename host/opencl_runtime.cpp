#include "host/opencl_runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <vector>

#include "core/common/errors.h"
#include "host/opencl_check.h"

namespace mq::cl {

namespace {

std::string platform_info(cl_platform_id p, cl_platform_info what) {
  std::size_t size = 0;
  MQ_CL_CHECK(clGetPlatformInfo(p, what, 0, nullptr, &size));
  std::string s(size, '\0');
  MQ_CL_CHECK(clGetPlatformInfo(p, what, size, s.data(), nullptr));
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

std::string device_info(cl_device_id d, cl_device_info what) {
  std::size_t size = 0;
  MQ_CL_CHECK(clGetDeviceInfo(d, what, 0, nullptr, &size));
  std::string s(size, '\0');
  MQ_CL_CHECK(clGetDeviceInfo(d, what, size, s.data(), nullptr));
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

std::vector<cl_platform_id> platforms() {
  cl_uint n = 0;
  const cl_int err = clGetPlatformIDs(0, nullptr, &n);
  if (err == -1001 /* CL_PLATFORM_NOT_FOUND_KHR */ || n == 0) return {};
  MQ_CL_CHECK(err);
  std::vector<cl_platform_id> ids(n);
  MQ_CL_CHECK(clGetPlatformIDs(n, ids.data(), nullptr));
  return ids;
}

std::vector<cl_device_id> devices(cl_platform_id p, cl_device_type type) {
  cl_uint n = 0;
  const cl_int err = clGetDeviceIDs(p, type, 0, nullptr, &n);
  if (err == CL_DEVICE_NOT_FOUND || n == 0) return {};
  MQ_CL_CHECK(err);
  std::vector<cl_device_id> ids(n);
  MQ_CL_CHECK(clGetDeviceIDs(p, type, n, ids.data(), nullptr));
  return ids;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool contains(const std::string& haystack, const std::string& needle) {
  return lower(haystack).find(lower(needle)) != std::string::npos;
}

std::string env_or(const std::string& value, const char* name) {
  if (!value.empty()) return value;
  const char* e = std::getenv(name);
  return e ? std::string(e) : std::string();
}

}  // namespace

bool Runtime::available() noexcept {
  try {
    return !platforms().empty();
  } catch (...) {
    return false;
  }
}

Runtime::Runtime(const RuntimeOptions& options) {
  const std::string want_platform = env_or(options.platform, "MESHQUILT_CL_PLATFORM");
  const std::string want_device = env_or(options.device, "MESHQUILT_CL_DEVICE");
  const std::vector<cl_platform_id> ps = platforms();
  MQ_CHECK(!ps.empty(), DeviceError, "no OpenCL platform is installed");

  if (!want_platform.empty() || !want_device.empty()) {
    std::string seen;
    for (cl_platform_id p : ps) {
      const std::string pname = platform_info(p, CL_PLATFORM_NAME);
      for (cl_device_id d : devices(p, CL_DEVICE_TYPE_ALL)) {
        const std::string dname = device_info(d, CL_DEVICE_NAME);
        seen.append(seen.empty() ? "\"" : ", \"").append(pname).append(" / ").append(dname);
        seen += '"';
        if (device_ || !contains(pname, want_platform) || !contains(dname, want_device)) continue;
        platform_ = p;
        device_ = d;
      }
    }
    MQ_CHECK(device_, DeviceError, "no OpenCL device matches platform \"", want_platform,
             "\" and device \"", want_device, "\"; available: ", seen);
  } else {
    for (cl_platform_id p : ps) {  // PoCL's CPU device
      if (!contains(platform_info(p, CL_PLATFORM_NAME), "Portable Computing Language")) continue;
      auto ds = devices(p, CL_DEVICE_TYPE_CPU);
      if (ds.empty()) ds = devices(p, CL_DEVICE_TYPE_ALL);
      if (!ds.empty()) {
        platform_ = p;
        device_ = ds.front();
        break;
      }
    }
    for (cl_device_type type :
         {cl_device_type(CL_DEVICE_TYPE_CPU), cl_device_type(CL_DEVICE_TYPE_ALL)})
      for (cl_platform_id p : ps) {
        if (device_) break;
        const auto ds = devices(p, type);
        if (!ds.empty()) {
          platform_ = p;
          device_ = ds.front();
        }
      }
    MQ_CHECK(device_, DeviceError, "no OpenCL device found on ", ps.size(), " platform(s)");
  }
  platform_name_ = platform_info(platform_, CL_PLATFORM_NAME);
  device_name_ = device_info(device_, CL_DEVICE_NAME);
  has_fp64_ = device_info(device_, CL_DEVICE_EXTENSIONS).find("cl_khr_fp64") != std::string::npos;

  cl_int err = CL_SUCCESS;
  const cl_context_properties props[] = {CL_CONTEXT_PLATFORM,
                                         reinterpret_cast<cl_context_properties>(platform_), 0};
  context_ = Context(clCreateContext(props, 1, &device_, nullptr, nullptr, &err));
  MQ_CL_CHECK(err);
  queue_ = CommandQueue(clCreateCommandQueue(context_.get(), device_, 0, &err));
  MQ_CL_CHECK(err);
  programs_ = std::make_unique<ProgramCache>(context_.get(), device_);
}

}  // namespace mq::cl
