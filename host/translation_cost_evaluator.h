// Choice between the CPU and OpenCL translation-cost evaluators.
#pragma once

#include <memory>

#include "core/planar/translation_cost.h"
#include "host/device.h"
#include "host/opencl_runtime.h"

namespace mq {

// Creates an evaluator. Cpu: the TBB path. OpenCL: the device path (problems under
// TranslationCostOpenCL::Options::min_device_pairs still answered on the host), created now;
// throws DeviceError when no usable device exists or the kernel does not build. Auto: the host
// path, creating the device path only when the first problem large enough for it arrives
// (nothing of OpenCL is loaded before), and keeping the host path when that fails; never
// throws for lack of a platform. Its name() says which path has answered so far. All paths
// give bitwise the same costs on PoCL.
std::unique_ptr<TranslationCostEvaluator> make_translation_cost_evaluator(
    Device which, const cl::RuntimeOptions& options = {});

}  // namespace mq
