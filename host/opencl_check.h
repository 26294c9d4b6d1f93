// Checking of OpenCL return codes: every call goes through MQ_CL_CHECK.
#pragma once

#include <CL/cl.h>

#include <string>

namespace mq::cl {

// The symbolic name of an OpenCL error code ("CL_OUT_OF_RESOURCES"), or "CL error <n>".
std::string error_name(cl_int code);

// Throws DeviceError naming the call, the error and the call site when code != CL_SUCCESS.
void check(cl_int code, const char* call, const char* file, int line);

}  // namespace mq::cl

#define MQ_CL_CHECK(call) ::mq::cl::check((call), #call, __FILE__, __LINE__)
