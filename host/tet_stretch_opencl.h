// OpenCL path of the per-tet shell-map stretch (paper section 3.2, Eq. 8); see
// core/shell/tet_stretch.h for the maths and kernels/tet_stretch.cl for the kernel.
#pragma once

#include <memory>
#include <string>

#include "core/shell/tet_stretch.h"
#include "host/opencl_handles.h"
#include "host/opencl_runtime.h"

namespace mq {

// One work-item per tet, double precision, FP_CONTRACT off: values agree with TetStretchCpu to
// rounding. Built for repeated calls from an optimisation that moves only texture_V: the shell
// vertices and the tets stay on the device (a host copy is compared on each call and uploaded
// again only when it changed), texture_V is written into a reused buffer, and the output
// buffer is reused while the tet count stays the same.
class TetStretchOpenCL final : public TetStretchEvaluator {
 public:
  // Builds the kernel through the runtime's program cache. Throws DeviceError when the device
  // lacks cl_khr_fp64 or the build fails; InvalidInput when runtime is null.
  explicit TetStretchOpenCL(std::shared_ptr<cl::Runtime> runtime);

  // Throws InvalidInput (validate_stretch_problem, or more than 2^31 - 1 tets); DeviceError.
  Eigen::VectorXd per_tet(const StretchProblem& problem) override;
  std::string name() const override { return "opencl"; }

  const cl::Runtime& runtime() const { return *runtime_; }
  // How many times the shell side (shell_V and T) has been uploaded.
  int num_shell_uploads() const { return num_shell_uploads_; }

 private:
  std::shared_ptr<cl::Runtime> runtime_;
  cl::Kernel kernel_;
  std::size_t group_ = 1;  // work-group size
  // Host copies of what the device buffers hold.
  MatrixX3d shell_V_;
  TetIndices T_;
  cl::Buffer shell_buffer_, tets_buffer_, texture_buffer_, out_buffer_;
  int num_shell_uploads_ = 0;
};

}  // namespace mq
