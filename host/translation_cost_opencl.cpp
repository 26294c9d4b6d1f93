#include "host/translation_cost_opencl.h"

#include <algorithm>
#include <vector>

#include "core/common/errors.h"
#include "host/opencl_buffers.h"
#include "kernels/translation_cost_cl.h"

namespace mq {

namespace {

// Trees kept on the device at once; beyond this the cache is flushed.
constexpr std::size_t kMaxCachedTrees = 4;
// Bound on #P * (offsets per launch), i.e. on the minima buffer (8 bytes each).
constexpr std::size_t kMaxMinimaPerLaunch = std::size_t(1) << 23;

// A read-only device copy of count values.
template <typename T>
cl::Buffer upload_array(cl_context context, const T* data, std::size_t count) {
  return cl::create_buffer(context, CL_MEM_READ_ONLY, sizeof(T) * count, data);
}

}  // namespace

TranslationCostOpenCL::TranslationCostOpenCL(std::shared_ptr<cl::Runtime> runtime,
                                             const Options& options)
    : runtime_(std::move(runtime)), options_(options) {
  MQ_CHECK(runtime_, InvalidInput, "TranslationCostOpenCL: null runtime");
  MQ_CHECK(runtime_->has_fp64(), DeviceError, "OpenCL device \"", runtime_->device_name(),
           "\" lacks cl_khr_fp64 (double precision), required by the translation-cost kernel");
  const cl_program program = runtime_->programs().get(kernels::translation_cost_source, "");
  cl_int err = CL_SUCCESS;
  kernel_ = cl::Kernel(clCreateKernel(program, "translation_cost_minima", &err));
  MQ_CL_CHECK(err);
  group_ = cl::work_group_size(kernel_.get(), runtime_->device());
}

const TranslationCostOpenCL::DeviceTree& TranslationCostOpenCL::upload(const SwatchFaceTree& tree) {
  auto it = trees_.find(tree.fingerprint());
  if (it != trees_.end()) return it->second;
  if (trees_.size() >= kMaxCachedTrees) trees_.clear();
  const cl_context ctx = runtime_->context();
  DeviceTree d;
  d.entry_triangles =
      upload_array(ctx, tree.entry_triangles().data(), tree.entry_triangles().size());
  d.entry_normals = upload_array(ctx, tree.entry_normals().data(), tree.entry_normals().size());
  d.entry_spheres = upload_array(ctx, tree.entry_spheres().data(), tree.entry_spheres().size());
  d.node_links = upload_array(ctx, tree.node_links().data(), tree.node_links().size());
  d.node_boxes = upload_array(ctx, tree.node_boxes().data(), tree.node_boxes().size());
  d.node_cones = upload_array(ctx, tree.node_cones().data(), tree.node_cones().size());
  return trees_.emplace(tree.fingerprint(), std::move(d)).first->second;
}

Eigen::VectorXd TranslationCostOpenCL::evaluate(const SwatchFaceTree& tree,
                                                const TranslationCostProblem& problem) {
  validate_translation_cost_problem(problem);
  const std::size_t P = static_cast<std::size_t>(problem.points.rows());
  const std::size_t T = static_cast<std::size_t>(problem.offsets.rows());
  Eigen::VectorXd E = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(T));
  if (P == 0 || T == 0) return E;
  if (!options_.on_device(problem)) return host_.evaluate(tree, problem);
  MQ_CHECK(P <= kMaxMinimaPerLaunch, InvalidInput, "translation cost: too many points (", P, ")");

  const DeviceTree& dt = upload(tree);
  const cl_context ctx = runtime_->context();
  const cl_command_queue queue = runtime_->queue();
  const cl::Buffer points = upload_array(ctx, problem.points.data(), problem.points.size());
  const cl::Buffer normals =
      upload_array(ctx, problem.point_normals.data(), problem.point_normals.size());
  const std::size_t chunk = std::min(T, std::max<std::size_t>(1, kMaxMinimaPerLaunch / P));
  const cl::Buffer out =
      cl::create_buffer(ctx, CL_MEM_WRITE_ONLY, sizeof(double) * P * chunk, nullptr);

  const cl_kernel k = kernel_.get();
  cl::set_arg(k, 0, points.get());
  cl::set_arg(k, 1, normals.get());
  cl::set_arg(k, 3, dt.entry_triangles.get());
  cl::set_arg(k, 4, dt.entry_normals.get());
  cl::set_arg(k, 5, dt.entry_spheres.get());
  cl::set_arg(k, 6, dt.node_links.get());
  cl::set_arg(k, 7, dt.node_boxes.get());
  cl::set_arg(k, 8, dt.node_cones.get());
  cl::set_arg(k, 9, tree.query_slack());
  cl::set_arg(k, 10, problem.lambda);
  cl::set_arg(k, 11, cl_int(P));
  cl::set_arg(k, 12, out.get());

  std::vector<double> minima(P * chunk);
  for (std::size_t t0 = 0; t0 < T; t0 += chunk) {
    const std::size_t nt = std::min(chunk, T - t0);
    const cl::Buffer offsets = upload_array(ctx, problem.offsets.data() + 3 * t0, 3 * nt);
    cl::set_arg(k, 2, offsets.get());
    const std::size_t global[2] = {cl::padded(P, group_), nt};
    const std::size_t local[2] = {group_, 1};
    MQ_CL_CHECK(clEnqueueNDRangeKernel(queue, k, 2, nullptr, global, local, 0, nullptr, nullptr));
    MQ_CL_CHECK(clEnqueueReadBuffer(queue, out.get(), CL_TRUE, 0, sizeof(double) * P * nt,
                                    minima.data(), 0, nullptr, nullptr));
    // Eq. (3), in point order as on the CPU.
    for (std::size_t t = 0; t < nt; ++t) {
      double s = 0.0;
      for (std::size_t p = 0; p < P; ++p) s += minima[t * P + p];
      E(static_cast<Eigen::Index>(t0 + t)) = s;
    }
  }
  return E;
}

}  // namespace mq
