// Both translation-cost paths (CPU/TBB and OpenCL) against the brute-force reference.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/planar/translation_cost.h"
#include "host/opencl_runtime.h"
#include "host/translation_cost_evaluator.h"
#include "host/translation_cost_opencl.h"
#include "tests/test_support.h"

namespace mq {
namespace {

using test::uniform;

// A sub-patch made of the swatch's own vertices (every stride-th one), moved by shift and
// optionally jittered by `noise` (positions) and 0.1 * noise / h (normals); offsets form a
// 5 x 5 grid with spacing `step` centred on `shift` (index 12 is the exact shift).
TranslationCostProblem self_subpatch(const TriMesh& m, int stride, const Vector3d& shift,
                                     double step, double noise, double lambda, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const MatrixX3d N = vertex_normals(m.V, m.F);
  const int P = (m.num_vertices() + stride - 1) / stride;
  TranslationCostProblem pb;
  pb.lambda = lambda;
  pb.points.resize(P, 3);
  pb.point_normals.resize(P, 3);
  for (int i = 0; i < P; ++i) {
    Vector3d v = Vector3d(m.V.row(i * stride)) + shift;
    Vector3d n = N.row(i * stride);
    if (noise > 0) {
      for (int a = 0; a < 3; ++a) v(a) += uniform(rng, -noise, noise);
      for (int a = 0; a < 3; ++a) n(a) += uniform(rng, -0.2, 0.2);
    }
    pb.points.row(i) = v;
    pb.point_normals.row(i) = n.normalized();
  }
  pb.offsets.resize(25, 3);
  for (int i = 0; i < 25; ++i) {
    const int row = i / 5;  // a 5 x 5 grid of offsets around the shift
    pb.offsets.row(i) = shift + Vector3d(step * (i % 5 - 2), step * (row - 2), 0.0);
  }
  return pb;
}

class TranslationCostPaths : public ::testing::TestWithParam<Device> {
 protected:
  // One runtime for the whole suite so that the kernel is built once.
  static void SetUpTestSuite() {
    if (cl::Runtime::available()) runtime_ = std::make_shared<cl::Runtime>();
  }
  static void TearDownTestSuite() { runtime_.reset(); }

  void SetUp() override {
    if (GetParam() == Device::Cpu) {
      evaluator_ = std::make_unique<TranslationCostCpu>();
    } else {
      if (!runtime_) GTEST_SKIP() << "no OpenCL platform";
      // Every problem on the device, however small (the default sends small ones to the host).
      TranslationCostOpenCL::Options options;
      options.min_device_pairs = 0;
      evaluator_ = std::make_unique<TranslationCostOpenCL>(runtime_, options);
    }
  }

  // All three agree per offset to relative 1e-4 and choose the same best offset; min_spread > 1
  // also checks that the costs differ enough across offsets for the test to mean something.
  void expect_agreement(const TriMesh& m, const TranslationCostProblem& pb,
                        double min_spread = 1.05) {
    const SwatchFaceTree tree(m.V, m.F);
    const Eigen::VectorXd fast = evaluator_->evaluate(tree, pb);
    const Eigen::VectorXd brute = translation_cost_brute_force(m.V, m.F, pb);
    ASSERT_EQ(fast.size(), brute.size());
    for (Eigen::Index t = 0; t < brute.size(); ++t) {
      ASSERT_TRUE(std::isfinite(brute(t)));
      EXPECT_LT(std::abs(fast(t) - brute(t)), 1e-4 * brute(t)) << "offset " << t;
    }
    EXPECT_EQ(best_offset(fast), best_offset(brute));
    if (min_spread > 1) {
      EXPECT_GT(brute.maxCoeff(), min_spread * brute.minCoeff());
    }
  }

  static std::shared_ptr<cl::Runtime> runtime_;
  std::unique_ptr<TranslationCostEvaluator> evaluator_;
};

std::shared_ptr<cl::Runtime> TranslationCostPaths::runtime_;

TEST_P(TranslationCostPaths, ExactShiftOfTorusSwatchWins) {
  const TriMesh m = read_mesh(test::shared_data("swatch/torus_576.off"));
  const double h = mean_edge_length(m.V, m.F);
  const TranslationCostProblem pb =
      self_subpatch(m, 2, Vector3d(3.1 * h, -1.7 * h, 0), 0.6 * h, 0.0, 1.0, 1);
  expect_agreement(m, pb);
  const SwatchFaceTree tree(m.V, m.F);
  EXPECT_EQ(best_offset(evaluator_->evaluate(tree, pb)), 12);
}

TEST_P(TranslationCostPaths, PerturbedTorusSubpatchLambdaNotOne) {
  const TriMesh m = read_mesh(test::shared_data("swatch/torus_576.off"));
  const double h = mean_edge_length(m.V, m.F);
  for (double lambda : {0.0, 0.3, 2.5}) {
    SCOPED_TRACE(lambda);
    // lambda = 0 leaves only the normal term, nearly flat across offsets.
    expect_agreement(
        m, self_subpatch(m, 3, Vector3d(0.5 * h, 0.2 * h, 0), 0.5 * h, 0.2 * h, lambda, 2),
        lambda > 0 ? 1.05 : 1.0);
  }
}

TEST_P(TranslationCostPaths, PerturbedChainlinkSubpatch) {
  const TriMesh m = read_mesh(test::shared_data("swatch/chainlink_half_12k.obj"));
  const double h = mean_edge_length(m.V, m.F);
  // ~100 points x 25 offsets x 11828 faces for the brute-force reference.
  const TranslationCostProblem pb =
      self_subpatch(m, 60, Vector3d(2 * h, 1 * h, 0), 0.8 * h, 0.3 * h, 1.0, 3);
  expect_agreement(m, pb);
}

TEST_P(TranslationCostPaths, PointsFarOutsideTheSwatch) {
  const TriMesh m = test::torus(2.0, 0.5, 24, 12);
  TranslationCostProblem pb = self_subpatch(m, 5, Vector3d(40, -25, 3), 0.4, 0.05, 1.5, 4);
  pb.offsets.array() *= 0.5;  // the points end up far from the translated swatch
  expect_agreement(m, pb, 1.02);
}

TEST_P(TranslationCostPaths, RepeatedEvaluationIsIdentical) {
  const TriMesh m = test::torus(2.0, 0.5, 32, 16);
  const TranslationCostProblem pb = self_subpatch(m, 3, Vector3d(0.3, 0.1, 0), 0.2, 0.02, 1, 5);
  const SwatchFaceTree tree(m.V, m.F);
  const Eigen::VectorXd a = evaluator_->evaluate(tree, pb);
  const Eigen::VectorXd b = evaluator_->evaluate(tree, pb);
  for (Eigen::Index t = 0; t < a.size(); ++t) EXPECT_EQ(a(t), b(t)) << "offset " << t;
}

// Each path's screening keeps the offsets a stable sort of its own costs keeps.
TEST_P(TranslationCostPaths, LeastCostOffsetsAreThoseOfItsCosts) {
  const TriMesh m = read_mesh(test::shared_data("swatch/torus_576.off"));
  const double h = mean_edge_length(m.V, m.F);
  const TranslationCostProblem pb =
      self_subpatch(m, 3, Vector3d(0.5 * h, 0.2 * h, 0), 0.5 * h, 0.2 * h, 1.0, 6);
  const SwatchFaceTree tree(m.V, m.F);
  const Eigen::VectorXd costs = evaluator_->evaluate(tree, pb);
  for (const int keep : {1, 3, 10}) {
    std::vector<int> expected(static_cast<size_t>(costs.size()));
    std::iota(expected.begin(), expected.end(), 0);
    std::stable_sort(expected.begin(), expected.end(),
                     [&](int a, int b) { return costs(a) < costs(b); });
    expected.resize(static_cast<size_t>(keep));
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(evaluator_->least_cost_offsets(tree, pb, keep).kept, expected) << "keep " << keep;
  }
}

TEST_P(TranslationCostPaths, EmptyProblem) {
  const TriMesh m = test::unit_cube();
  const SwatchFaceTree tree(m.V, m.F);
  TranslationCostProblem pb;  // no points, no offsets
  EXPECT_EQ(evaluator_->evaluate(tree, pb).size(), 0);
  pb.offsets = MatrixX3d::Zero(3, 3);  // offsets but no points: E(t) = 0
  const Eigen::VectorXd E = evaluator_->evaluate(tree, pb);
  ASSERT_EQ(E.size(), 3);
  EXPECT_EQ(E.cwiseAbs().maxCoeff(), 0.0);
  pb.points = MatrixX3d::Constant(2, 3, 0.5);  // points but no offsets
  pb.point_normals = MatrixX3d::Zero(2, 3);
  pb.offsets.resize(0, 3);
  EXPECT_EQ(evaluator_->evaluate(tree, pb).size(), 0);
}

TEST_P(TranslationCostPaths, InvalidInputThrows) {
  const TriMesh m = test::unit_cube();
  const SwatchFaceTree tree(m.V, m.F);
  TranslationCostProblem good;
  good.points = MatrixX3d::Constant(2, 3, 0.5);
  good.point_normals = MatrixX3d::Zero(2, 3);
  good.offsets = MatrixX3d::Zero(1, 3);
  EXPECT_NO_THROW(evaluator_->evaluate(tree, good));
  TranslationCostProblem pb = good;
  pb.point_normals = MatrixX3d::Zero(3, 3);
  EXPECT_THROW(evaluator_->evaluate(tree, pb), InvalidInput);
  pb = good;
  pb.points(1, 2) = std::nan("");
  EXPECT_THROW(evaluator_->evaluate(tree, pb), InvalidInput);
  pb = good;
  pb.point_normals(0, 0) = std::nan("");
  EXPECT_THROW(evaluator_->evaluate(tree, pb), InvalidInput);
  pb = good;
  pb.offsets(0, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(evaluator_->evaluate(tree, pb), InvalidInput);
  pb = good;
  pb.lambda = -1.0;
  EXPECT_THROW(evaluator_->evaluate(tree, pb), InvalidInput);
  pb.lambda = std::nan("");
  EXPECT_THROW(evaluator_->evaluate(tree, pb), InvalidInput);
}

INSTANTIATE_TEST_SUITE_P(Paths, TranslationCostPaths,
                         ::testing::Values(Device::Cpu, Device::OpenCL),
                         [](const ::testing::TestParamInfo<Device>& info) {
                           return info.param == Device::Cpu ? "Cpu" : "OpenCL";
                         });

TEST(TranslationCostOpenCL, SwatchGridIsUploadedOncePerGrid) {
  if (!cl::Runtime::available()) GTEST_SKIP() << "no OpenCL platform";
  TranslationCostOpenCL::Options options;
  options.min_device_pairs = 0;
  TranslationCostOpenCL ocl(std::make_shared<cl::Runtime>(), options);
  const TriMesh a = test::torus(2.0, 0.5, 16, 8), b = test::unit_cube();
  const SwatchFaceTree ga(a.V, a.F), gb(b.V, b.F);
  TranslationCostProblem pb;
  pb.points = MatrixX3d::Constant(4, 3, 0.25);
  pb.point_normals = MatrixX3d::Zero(4, 3);
  pb.offsets = MatrixX3d::Zero(2, 3);
  const Eigen::VectorXd first = ocl.evaluate(ga, pb);
  EXPECT_EQ(ocl.num_cached_trees(), 1u);
  ocl.evaluate(ga, pb);
  EXPECT_EQ(ocl.num_cached_trees(), 1u);
  const Eigen::VectorXd cube = ocl.evaluate(gb, pb);
  EXPECT_EQ(ocl.num_cached_trees(), 2u);
  // The cached buffers belong to the right tree.
  EXPECT_EQ(ocl.evaluate(ga, pb)(0), first(0));
  EXPECT_NE(cube(0), first(0));
}

// Below min_device_pairs the host path answers (nothing is uploaded) with the same costs; at or
// above it the kernel runs.
// The first num_points vertices of a small torus (with their normals) against num_offsets
// offsets along x, 0.01 apart.
TranslationCostProblem torus_problem(const TriMesh& torus, int num_points, int num_offsets) {
  TranslationCostProblem pb;
  pb.points = torus.V.topRows(num_points);
  pb.point_normals = vertex_normals(torus.V, torus.F).topRows(num_points);
  pb.offsets = MatrixX3d::Zero(num_offsets, 3);
  for (int i = 0; i < num_offsets; ++i) pb.offsets(i, 0) = 0.01 * i;
  return pb;
}

TEST(TranslationCostOpenCL, SmallProblemsStayOnTheHost) {
  if (!cl::Runtime::available()) GTEST_SKIP() << "no OpenCL platform";
  TranslationCostOpenCL::Options options;
  options.min_device_pairs = 8;
  TranslationCostOpenCL ocl(std::make_shared<cl::Runtime>(), options);
  const TriMesh m = test::torus(2.0, 0.5, 16, 8);
  const SwatchFaceTree tree(m.V, m.F);
  TranslationCostProblem pb = torus_problem(m, 3, 2);
  TranslationCostCpu cpu;
  const Eigen::VectorXd small = ocl.evaluate(tree, pb);  // 6 pairs
  EXPECT_EQ(ocl.num_cached_trees(), 0u);
  EXPECT_EQ(small, cpu.evaluate(tree, pb));
  pb = torus_problem(m, 4, 2);
  const Eigen::VectorXd large = ocl.evaluate(tree, pb);  // 8 pairs
  EXPECT_EQ(ocl.num_cached_trees(), 1u);
  const Eigen::VectorXd reference = cpu.evaluate(tree, pb);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(large(i), reference(i), 1e-9 * reference(i));
}

TEST(TranslationCostFactory, ChoosesThePath) {
  EXPECT_EQ(make_translation_cost_evaluator(Device::Cpu)->name(), "cpu");
  if (cl::Runtime::available()) {
    EXPECT_EQ(make_translation_cost_evaluator(Device::OpenCL)->name(), "opencl");
  } else {
    EXPECT_THROW(make_translation_cost_evaluator(Device::OpenCL), DeviceError);
  }
  // Auto answers small problems on the host without touching OpenCL, and takes the device (when
  // there is one) for the first problem of min_device_pairs pairs; the costs are the same.
  const auto automatic = make_translation_cost_evaluator(Device::Auto);
  const TriMesh m = test::torus(2.0, 0.5, 16, 8);
  const SwatchFaceTree tree(m.V, m.F);
  TranslationCostProblem pb = torus_problem(m, 64, 4);
  TranslationCostCpu cpu;
  EXPECT_EQ(automatic->evaluate(tree, pb), cpu.evaluate(tree, pb));
  EXPECT_EQ(automatic->name(), "cpu");
  const int enough = static_cast<int>(TranslationCostOpenCL::Options().min_device_pairs / 64 + 1);
  pb = torus_problem(m, 64, enough);
  const Eigen::VectorXd large = automatic->evaluate(tree, pb);
  EXPECT_EQ(automatic->name(), cl::Runtime::available() ? "opencl" : "cpu");
  const Eigen::VectorXd reference = cpu.evaluate(tree, pb);
  ASSERT_EQ(large.size(), reference.size());
  for (Eigen::Index i = 0; i < large.size(); ++i)
    EXPECT_NEAR(large(i), reference(i), 1e-9 * reference(i)) << "offset " << i;
}

}  // namespace
}  // namespace mq
