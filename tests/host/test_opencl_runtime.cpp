#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "core/common/errors.h"
#include "host/opencl_runtime.h"
#include "host/program_cache.h"

namespace mq::cl {
namespace {

class OpenClRuntime : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!Runtime::available()) GTEST_SKIP() << "no OpenCL platform";
  }
};

// Sets an environment variable for the scope of one test.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);
    had_ = old != nullptr;
    if (had_) old_ = old;
    setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (had_)
      setenv(name_.c_str(), old_.c_str(), 1);
    else
      unsetenv(name_.c_str());
  }

 private:
  std::string name_, old_;
  bool had_ = false;
};

constexpr const char* kAddSource = R"(
__kernel void add(__global float* x, const float a) { x[get_global_id(0)] += a + OFFSET; }
)";

TEST_F(OpenClRuntime, DefaultsToPoclCpuDevice) {
  ScopedEnv p("MESHQUILT_CL_PLATFORM", ""), d("MESHQUILT_CL_DEVICE", "");
  const Runtime rt;
  EXPECT_NE(rt.context(), nullptr);
  EXPECT_NE(rt.queue(), nullptr);
  EXPECT_NE(rt.platform_name().find("Portable Computing Language"), std::string::npos)
      << rt.platform_name();
  EXPECT_TRUE(rt.has_fp64());  // PoCL's CPU device
}

TEST_F(OpenClRuntime, SelectsBySubstringAndRejectsUnknownDevices) {
  const Runtime rt;
  RuntimeOptions options;
  options.device = rt.device_name().substr(0, 4);
  options.platform = "portable";  // case-insensitive
  EXPECT_EQ(Runtime(options).device(), rt.device());
  options.device = "no-such-device-xyz";
  try {
    Runtime bad(options);
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-device-xyz"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(rt.device_name()), std::string::npos) << e.what();
  }
}

TEST_F(OpenClRuntime, EnvironmentVariablesChooseTheDevice) {
  const std::string device_name = Runtime().device_name();
  {
    ScopedEnv d("MESHQUILT_CL_DEVICE", "no-such-device-xyz");
    EXPECT_THROW(Runtime(), DeviceError);
    RuntimeOptions options;  // an explicit option overrides the environment
    options.device = device_name;
    EXPECT_EQ(Runtime(options).device_name(), device_name);
  }
  {
    ScopedEnv d("MESHQUILT_CL_DEVICE", device_name.c_str());
    EXPECT_EQ(Runtime().device_name(), device_name);
  }
  ScopedEnv p("MESHQUILT_CL_PLATFORM", "no-such-platform-xyz");
  EXPECT_THROW(Runtime(), DeviceError);
}

TEST_F(OpenClRuntime, ProgramCacheReusesBuiltPrograms) {
  Runtime rt;
  ProgramCache& cache = rt.programs();
  const cl_program a = cache.get(kAddSource, "-DOFFSET=1.0f");
  const cl_program b = cache.get(kAddSource, "-DOFFSET=1.0f");
  EXPECT_EQ(a, b);
  EXPECT_EQ(cache.size(), 1u);
  const cl_program c = cache.get(kAddSource, "-DOFFSET=2.0f");
  EXPECT_NE(a, c);
  EXPECT_EQ(cache.size(), 2u);
  const cl_program d = cache.get(std::string(kAddSource) + "\n", "-DOFFSET=1.0f");
  EXPECT_NE(a, d);
  EXPECT_EQ(cache.size(), 3u);
  // The cached program really is usable.
  cl_int err = CL_SUCCESS;
  Kernel k(clCreateKernel(a, "add", &err));
  EXPECT_EQ(err, CL_SUCCESS);
}

TEST_F(OpenClRuntime, BuildFailureReportsTheBuildLog) {
  Runtime rt;
  const std::string broken =
      "__kernel void broken(__global float* x) { x[0] = undeclared_thing_42 + ; }\n";
  try {
    rt.programs().get(broken, "");
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("CL_BUILD_PROGRAM_FAILURE"), std::string::npos) << msg;
    // The compiler's own diagnostic, naming the offending identifier.
    EXPECT_NE(msg.find("undeclared_thing_42"), std::string::npos) << msg;
    EXPECT_NE(msg.find("error"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one-line message";
  }
  EXPECT_EQ(rt.programs().size(), 0u);
  // Unknown options are a build failure too, not a crash.
  EXPECT_THROW(rt.programs().get(kAddSource, "-DOFFSET=1.0f --no-such-option"), DeviceError);
}

}  // namespace
}  // namespace mq::cl
