// Checked buffer creation, kernel arguments and launch sizes shared by the kernel launchers.
#pragma once

#include <cstddef>

#include "host/opencl_check.h"
#include "host/opencl_handles.h"

namespace mq::cl {

// A device buffer of `bytes` bytes, copied from `data` when it is non-null. OpenCL rejects
// zero-sized buffers, so an empty request gets one byte that is never read.
// Throws DeviceError naming the failing call.
Buffer create_buffer(cl_context context, cl_mem_flags flags, std::size_t bytes, const void* data);

// Work-group size for a 1D-indexed kernel: min(preferred, CL_KERNEL_WORK_GROUP_SIZE on device).
// Launches use a fixed work-group size and a global size padded to a multiple of it (the
// kernels ignore the padding items): PoCL compiles one work-group function per distinct local
// size, so letting it pick sizes from ever-changing global sizes recompiled the kernel on many
// launches (measured: OpenCL matching 3.5x slower than the TBB path on a surface job).
// Throws DeviceError naming the failing call.
std::size_t work_group_size(cl_kernel kernel, cl_device_id device, std::size_t preferred = 64);

// n rounded up to a multiple of group (group >= 1).
inline std::size_t padded(std::size_t n, std::size_t group) {
  return (n + group - 1) / group * group;
}

// clSetKernelArg for a value or a cl_mem handle, checked.
template <typename T>
void set_arg(cl_kernel kernel, cl_uint index, const T& value) {
  // sizeof(T) is the size OpenCL wants, also for a cl_mem (a pointer to an opaque struct).
  // NOLINTNEXTLINE(bugprone-sizeof-expression)
  MQ_CL_CHECK(clSetKernelArg(kernel, index, sizeof(T), &value));
}

}  // namespace mq::cl
