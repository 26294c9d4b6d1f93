// Checked buffer creation and kernel arguments shared by the kernel launchers.
#pragma once

#include <cstddef>

#include "host/opencl_check.h"
#include "host/opencl_handles.h"

namespace mq::cl {

// A device buffer of `bytes` bytes, copied from `data` when it is non-null. OpenCL rejects
// zero-sized buffers, so an empty request gets one byte that is never read.
// Throws DeviceError naming the failing call.
Buffer create_buffer(cl_context context, cl_mem_flags flags, std::size_t bytes, const void* data);

// clSetKernelArg for a value or a cl_mem handle, checked.
template <typename T>
void set_arg(cl_kernel kernel, cl_uint index, const T& value) {
  MQ_CL_CHECK(clSetKernelArg(kernel, index, sizeof(T), &value));
}

}  // namespace mq::cl
