#include "host/tet_stretch_evaluator.h"

#include "host/tet_stretch_opencl.h"

namespace mq {

std::unique_ptr<TetStretchEvaluator> make_tet_stretch_evaluator(Device which,
                                                                const cl::RuntimeOptions& options) {
  if (which == Device::Cpu) return std::make_unique<TetStretchCpu>();
  if (which == Device::Auto && !cl::Runtime::available()) return std::make_unique<TetStretchCpu>();
  auto runtime = std::make_shared<cl::Runtime>(options);
  if (which == Device::Auto && !runtime->has_fp64()) return std::make_unique<TetStretchCpu>();
  return std::make_unique<TetStretchOpenCL>(std::move(runtime));
}

}  // namespace mq
