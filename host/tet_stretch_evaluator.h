// Choice between the CPU and OpenCL tet-stretch evaluators.
#pragma once

#include <memory>

#include "core/shell/tet_stretch.h"
#include "host/device.h"
#include "host/opencl_runtime.h"

namespace mq {

// Creates an evaluator. Throws DeviceError for Device::OpenCL when no usable device exists (or
// the kernel does not build); Auto never fails for lack of a platform.
std::unique_ptr<TetStretchEvaluator> make_tet_stretch_evaluator(
    Device which, const cl::RuntimeOptions& options = {});

}  // namespace mq
