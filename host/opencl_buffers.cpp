#include "host/opencl_buffers.h"

#include <algorithm>

namespace mq::cl {

Buffer create_buffer(cl_context context, cl_mem_flags flags, std::size_t bytes, const void* data) {
  cl_int err = CL_SUCCESS;
  const bool copy = data != nullptr && bytes > 0;
  Buffer b(clCreateBuffer(context, flags | (copy ? CL_MEM_COPY_HOST_PTR : 0),
                          std::max<std::size_t>(bytes, 1), copy ? const_cast<void*>(data) : nullptr,
                          &err));
  MQ_CL_CHECK(err);
  return b;
}

std::size_t work_group_size(cl_kernel kernel, cl_device_id device, std::size_t preferred) {
  std::size_t max_size = 0;
  MQ_CL_CHECK(clGetKernelWorkGroupInfo(kernel, device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(max_size),
                                       &max_size, nullptr));
  return std::max<std::size_t>(1, std::min(preferred, max_size));
}

}  // namespace mq::cl
