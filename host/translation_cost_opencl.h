// OpenCL path of the translation cost (paper section 2.4, Eqs. (1)-(3)); see
// core/planar/translation_cost.h for the maths and kernels/translation_cost.cl for the kernel.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "core/planar/translation_cost.h"
#include "host/opencl_handles.h"
#include "host/opencl_runtime.h"

namespace mq {

// Evaluates all offsets in one 2D launch (points x offsets, split into chunks only to bound the
// per-(point, offset) minima buffer); the host sums each offset in point order, so results are
// deterministic and use the same summation order as the CPU path. Runs in double precision;
// per-offset costs agree with the CPU path to rounding (FP_CONTRACT is off in the kernel; on
// PoCL's CPU device they came out bitwise identical).
// Swatch trees are uploaded once and cached by their fingerprint (a few trees at a time).
class TranslationCostOpenCL final : public TranslationCostEvaluator {
 public:
  struct Options {
    // Problems with fewer (point, offset) pairs than this are evaluated by the host path
    // (TranslationCostCpu, the same tree and maths, bitwise the same sums on PoCL): a launch
    // with its transfers costs PoCL ~0.7 ms, more than the host needs for a few thousand
    // pairs (bench/translation_cost_bench, BM_TranslationCost*Small). 0 = always the device.
    std::size_t min_device_pairs = 16384;
    // Whether a problem is large enough for the device under this rule.
    bool on_device(const TranslationCostProblem& problem) const {
      return static_cast<std::size_t>(problem.points.rows()) *
                 static_cast<std::size_t>(problem.offsets.rows()) >=
             min_device_pairs;
    }
  };

  // Builds the kernel through the runtime's program cache. Throws DeviceError when the device
  // lacks cl_khr_fp64 or the build fails; InvalidInput when runtime is null.
  explicit TranslationCostOpenCL(std::shared_ptr<cl::Runtime> runtime)
      : TranslationCostOpenCL(std::move(runtime), Options()) {}
  TranslationCostOpenCL(std::shared_ptr<cl::Runtime> runtime, const Options& options);

  Eigen::VectorXd evaluate(const SwatchFaceTree& tree,
                           const TranslationCostProblem& problem) override;
  std::string name() const override { return "opencl"; }

  const cl::Runtime& runtime() const { return *runtime_; }
  // Number of swatch trees currently held on the device.
  std::size_t num_cached_trees() const { return trees_.size(); }

 private:
  struct DeviceTree {
    cl::Buffer entry_triangles, entry_normals, entry_spheres, node_links, node_boxes, node_cones;
  };
  const DeviceTree& upload(const SwatchFaceTree& tree);

  std::shared_ptr<cl::Runtime> runtime_;
  Options options_;
  TranslationCostCpu host_;  // below options_.min_device_pairs
  cl::Kernel kernel_;
  std::size_t group_ = 1;  // work-group size along the points
  std::map<std::uint64_t, DeviceTree> trees_;
};

}  // namespace mq
