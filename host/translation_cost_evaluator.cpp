#include "host/translation_cost_evaluator.h"

#include <utility>

#include "core/common/errors.h"
#include "host/translation_cost_opencl.h"

namespace mq {

namespace {

// Device::Auto: the host path until a problem large enough for the device arrives; only then
// are the OpenCL runtime and kernel created (their start-up, ~0.07 s on PoCL, would otherwise
// be the only thing a run of screened matching problems, all small, spends on OpenCL). When no
// usable device exists, the host path answers for good.
class TranslationCostAuto final : public TranslationCostEvaluator {
 public:
  explicit TranslationCostAuto(cl::RuntimeOptions options) : options_(std::move(options)) {}

  Eigen::VectorXd evaluate(const SwatchFaceTree& tree,
                           const TranslationCostProblem& problem) override {
    if (!TranslationCostOpenCL::Options().on_device(problem)) return host_.evaluate(tree, problem);
    TranslationCostEvaluator* device = device_path();
    return device ? device->evaluate(tree, problem) : host_.evaluate(tree, problem);
  }

  LeastCostOffsets least_cost_offsets(const SwatchFaceTree& tree,
                                      const TranslationCostProblem& problem, int keep) override {
    if (!TranslationCostOpenCL::Options().on_device(problem))
      return host_.least_cost_offsets(tree, problem, keep);
    TranslationCostEvaluator* device = device_path();
    return device ? device->least_cost_offsets(tree, problem, keep)
                  : host_.least_cost_offsets(tree, problem, keep);
  }

  // What has answered so far: "opencl" once the device took a problem, else "cpu".
  std::string name() const override { return device_ ? device_->name() : host_.name(); }

 private:
  // The device evaluator, created on first use; null when there is no usable device.
  TranslationCostEvaluator* device_path() {
    if (!tried_device_) {
      tried_device_ = true;
      try {
        if (cl::Runtime::available()) {
          auto runtime = std::make_shared<cl::Runtime>(options_);
          if (runtime->has_fp64()) device_ = std::make_unique<TranslationCostOpenCL>(runtime);
        }
      } catch (const DeviceError&) {
        device_.reset();  // no usable device: the host path is the answer
      }
    }
    return device_.get();
  }

  cl::RuntimeOptions options_;
  TranslationCostCpu host_;
  std::unique_ptr<TranslationCostOpenCL> device_;
  bool tried_device_ = false;
};

}  // namespace

std::unique_ptr<TranslationCostEvaluator> make_translation_cost_evaluator(
    Device which, const cl::RuntimeOptions& options) {
  if (which == Device::Cpu) return std::make_unique<TranslationCostCpu>();
  if (which == Device::Auto) return std::make_unique<TranslationCostAuto>(options);
  return std::make_unique<TranslationCostOpenCL>(std::make_shared<cl::Runtime>(options));
}

}  // namespace mq
