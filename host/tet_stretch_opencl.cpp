#include "host/tet_stretch_opencl.h"

#include <limits>

#include "core/common/errors.h"
#include "host/opencl_buffers.h"
#include "kernels/tet_stretch_cl.h"

namespace mq {

TetStretchOpenCL::TetStretchOpenCL(std::shared_ptr<cl::Runtime> runtime)
    : runtime_(std::move(runtime)) {
  MQ_CHECK(runtime_, InvalidInput, "TetStretchOpenCL: null runtime");
  MQ_CHECK(runtime_->has_fp64(), DeviceError, "OpenCL device \"", runtime_->device_name(),
           "\" lacks cl_khr_fp64 (double precision), required by the tet-stretch kernel");
  const cl_program program = runtime_->programs().get(kernels::tet_stretch_source, "");
  cl_int err = CL_SUCCESS;
  kernel_ = cl::Kernel(clCreateKernel(program, "tet_stretch", &err));
  MQ_CL_CHECK(err);
  group_ = cl::work_group_size(kernel_.get(), runtime_->device());
}

Eigen::VectorXd TetStretchOpenCL::per_tet(const StretchProblem& pb) {
  validate_stretch_problem(pb);
  MQ_CHECK(pb.T.rows() <= std::numeric_limits<int>::max(), InvalidInput,
           "tet stretch: too many tets (", pb.T.rows(), ")");
  const std::size_t nt = static_cast<std::size_t>(pb.T.rows());
  Eigen::VectorXd out(pb.T.rows());
  if (nt == 0) return out;
  const cl_context ctx = runtime_->context();
  const cl_command_queue queue = runtime_->queue();
  const std::size_t vbytes = sizeof(double) * static_cast<std::size_t>(pb.shell_V.size());

  // The shell side changes rarely: compare with what the device holds.
  const bool same_shell = shell_buffer_ && shell_V_.rows() == pb.shell_V.rows() &&
                          T_.rows() == pb.T.rows() && shell_V_ == pb.shell_V && T_ == pb.T;
  if (!same_shell) {
    const std::size_t tbytes = sizeof(int) * 4 * nt;
    shell_buffer_ = cl::create_buffer(ctx, CL_MEM_READ_ONLY, vbytes, pb.shell_V.data());
    tets_buffer_ = cl::create_buffer(ctx, CL_MEM_READ_ONLY, tbytes, pb.T.data());
    texture_buffer_ = cl::create_buffer(ctx, CL_MEM_READ_ONLY, vbytes, nullptr);
    out_buffer_ = cl::create_buffer(ctx, CL_MEM_WRITE_ONLY, sizeof(double) * nt, nullptr);
    shell_V_ = pb.shell_V;
    T_ = pb.T;
    ++num_shell_uploads_;
  }
  MQ_CL_CHECK(clEnqueueWriteBuffer(queue, texture_buffer_.get(), CL_FALSE, 0, vbytes,
                                   pb.texture_V.data(), 0, nullptr, nullptr));
  const cl_kernel k = kernel_.get();
  cl::set_arg(k, 0, shell_buffer_.get());
  cl::set_arg(k, 1, texture_buffer_.get());
  cl::set_arg(k, 2, tets_buffer_.get());
  cl::set_arg(k, 3, cl_int(nt));
  cl::set_arg(k, 4, out_buffer_.get());
  const std::size_t global = cl::padded(nt, group_), local = group_;
  MQ_CL_CHECK(clEnqueueNDRangeKernel(queue, k, 1, nullptr, &global, &local, 0, nullptr, nullptr));
  MQ_CL_CHECK(clEnqueueReadBuffer(queue, out_buffer_.get(), CL_TRUE, 0, sizeof(double) * nt,
                                  out.data(), 0, nullptr, nullptr));
  return out;
}

}  // namespace mq
