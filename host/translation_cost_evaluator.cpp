#include "host/translation_cost_evaluator.h"

#include "host/translation_cost_opencl.h"

namespace mq {

std::unique_ptr<TranslationCostEvaluator> make_translation_cost_evaluator(
    Device which, const cl::RuntimeOptions& options) {
  if (which == Device::Cpu) return std::make_unique<TranslationCostCpu>();
  if (which == Device::Auto && !cl::Runtime::available())
    return std::make_unique<TranslationCostCpu>();
  auto runtime = std::make_shared<cl::Runtime>(options);
  if (which == Device::Auto && !runtime->has_fp64()) return std::make_unique<TranslationCostCpu>();
  return std::make_unique<TranslationCostOpenCL>(std::move(runtime));
}

}  // namespace mq
