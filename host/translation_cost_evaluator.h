// Choice between the CPU and OpenCL translation-cost evaluators.
#pragma once

#include <memory>

#include "core/translation_cost.h"
#include "host/opencl_runtime.h"

namespace mq {

enum class Device {
  Cpu,     // TBB path
  OpenCL,  // kernel on the device chosen by RuntimeOptions / environment
  Auto,    // OpenCL when a platform with a double-precision device exists, else CPU
};

// Creates an evaluator. Throws DeviceError for Device::OpenCL when no usable device exists (or
// the kernel does not build); Auto never fails for lack of a platform.
std::unique_ptr<TranslationCostEvaluator> make_translation_cost_evaluator(
    Device which, const cl::RuntimeOptions& options = {});

}  // namespace mq
