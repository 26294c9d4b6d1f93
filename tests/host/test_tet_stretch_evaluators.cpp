// Both tet-stretch paths (CPU/TBB and OpenCL) against the reference (paper section 3.2, Eq. 8).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/common/errors.h"
#include "core/shell/shell_tetrahedra.h"
#include "core/shell/tet_stretch.h"
#include "host/opencl_runtime.h"
#include "host/tet_stretch_evaluator.h"
#include "host/tet_stretch_opencl.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

using test::uniform;

// The bunny's shell at 2% of its diagonal, built once.
const StretchProblem& bunny_shell() {
  static const StretchProblem pb = [] {
    const test::OffsetBase ob = test::offset_base("base/bunny_igl_7k.off");
    const TetMesh shell = shell_tetrahedra(ob.base.V, ob.offset.V, ob.base.F);
    return StretchProblem{shell.V, shell.V, shell.T};
  }();
  return pb;
}

// Texture = a scaled copy of the shell with every vertex jittered by up to `noise` (relative to
// the bbox diagonal), so some tets fold when noise is large.
StretchProblem perturbed(const StretchProblem& base, double noise, std::uint64_t seed) {
  StretchProblem pb = base;
  std::mt19937_64 rng(seed);
  const double diag = (pb.shell_V.colwise().maxCoeff() - pb.shell_V.colwise().minCoeff()).norm();
  for (Eigen::Index i = 0; i < pb.texture_V.rows(); ++i)
    for (int a = 0; a < 3; ++a)
      pb.texture_V(i, a) = 3.0 * pb.texture_V(i, a) + uniform(rng, -noise, noise) * diag;
  return pb;
}

class TetStretchPaths : public ::testing::TestWithParam<Device> {
 protected:
  static void SetUpTestSuite() {
    if (cl::Runtime::available()) runtime_ = std::make_shared<cl::Runtime>();
  }
  static void TearDownTestSuite() { runtime_.reset(); }

  void SetUp() override {
    if (GetParam() == Device::Cpu) {
      evaluator_ = std::make_unique<TetStretchCpu>();
    } else {
      if (!runtime_) GTEST_SKIP() << "no OpenCL platform";
      evaluator_ = std::make_unique<TetStretchOpenCL>(runtime_);
    }
  }

  // Per tet within 1e-9 relative of the reference; infinite exactly where it is.
  void expect_agreement(const StretchProblem& pb) {
    const Eigen::VectorXd fast = evaluator_->per_tet(pb), ref = tet_stretch_reference(pb);
    ASSERT_EQ(fast.size(), ref.size());
    for (Eigen::Index t = 0; t < ref.size(); ++t) {
      if (std::isinf(ref(t))) {
        ASSERT_TRUE(std::isinf(fast(t))) << "tet " << t;
      } else {
        ASSERT_LE(std::abs(fast(t) - ref(t)), 1e-9 * ref(t)) << "tet " << t;
      }
    }
  }

  static std::shared_ptr<cl::Runtime> runtime_;
  std::unique_ptr<TetStretchEvaluator> evaluator_;
};

std::shared_ptr<cl::Runtime> TetStretchPaths::runtime_;

TEST_P(TetStretchPaths, IdentityOnBunnyShellIsOne) {
  const StretchProblem& pb = bunny_shell();
  const Eigen::VectorXd per = evaluator_->per_tet(pb);
  ASSERT_EQ(per.size(), pb.T.rows());
  EXPECT_NEAR((per.array() - 1.0).abs().maxCoeff(), 0.0, 1e-9);
  EXPECT_NEAR(total_stretch(pb, per), 1.0, 1e-12);
}

TEST_P(TetStretchPaths, MatchesReferenceOnPerturbedBunnyShell) {
  // Small jitter: every tet stays valid and the stretch varies; large: some tets fold (inf).
  for (const double noise : {1e-4, 3e-3}) {
    SCOPED_TRACE(noise);
    const StretchProblem pb = perturbed(bunny_shell(), noise, 17);
    expect_agreement(pb);
    const Eigen::VectorXd ref = tet_stretch_reference(pb);
    const auto finite = (ref.array() < std::numeric_limits<double>::infinity());
    EXPECT_GT(finite.count(), ref.size() / 2);
    if (noise > 1e-3) {
      EXPECT_LT(finite.count(), ref.size());  // the case of folded tets is exercised
    } else {
      EXPECT_EQ(finite.count(), ref.size());
      EXPECT_GT(total_stretch(pb, ref), 1.0);
    }
  }
}

TEST_P(TetStretchPaths, MovingTextureReusesTheShellBuffers) {
  const StretchProblem& base = bunny_shell();
  for (std::uint64_t seed = 1; seed <= 3; ++seed) expect_agreement(perturbed(base, 1e-4, seed));
  if (auto* ocl = dynamic_cast<TetStretchOpenCL*>(evaluator_.get())) {
    EXPECT_EQ(ocl->num_shell_uploads(), 1);
    // A different shell is uploaded again and gives its own values.
    StretchProblem other = perturbed(base, 1e-4, 9);
    other.shell_V *= 2.0;
    expect_agreement(other);
    EXPECT_EQ(ocl->num_shell_uploads(), 2);
  }
}

TEST_P(TetStretchPaths, RepeatedEvaluationIsIdentical) {
  const StretchProblem pb = perturbed(bunny_shell(), 1e-3, 4);
  EXPECT_TRUE(evaluator_->per_tet(pb) == evaluator_->per_tet(pb));
}

TEST_P(TetStretchPaths, EmptyAndInvalidInput) {
  EXPECT_EQ(evaluator_->per_tet(StretchProblem{}).size(), 0);
  StretchProblem good;
  good.shell_V.resize(4, 3);
  good.shell_V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  good.texture_V = good.shell_V;
  good.T.resize(1, 4);
  good.T << 0, 1, 2, 3;
  EXPECT_NEAR(evaluator_->per_tet(good)(0), 1.0, 1e-15);
  StretchProblem pb = good;
  pb.texture_V.conservativeResize(3, 3);
  EXPECT_THROW(evaluator_->per_tet(pb), InvalidInput);
  pb = good;
  pb.texture_V(2, 2) = std::nan("");
  EXPECT_THROW(evaluator_->per_tet(pb), InvalidInput);
  pb = good;
  pb.T(0, 3) = 4;
  EXPECT_THROW(evaluator_->per_tet(pb), InvalidInput);
  pb = good;
  pb.texture_V.row(3) = pb.texture_V.row(0);  // flat texture tet
  EXPECT_EQ(evaluator_->per_tet(pb)(0), std::numeric_limits<double>::infinity());
}

INSTANTIATE_TEST_SUITE_P(Paths, TetStretchPaths, ::testing::Values(Device::Cpu, Device::OpenCL),
                         [](const ::testing::TestParamInfo<Device>& info) {
                           return info.param == Device::Cpu ? "Cpu" : "OpenCL";
                         });

TEST(TetStretchFactory, ChoosesThePath) {
  EXPECT_EQ(make_tet_stretch_evaluator(Device::Cpu)->name(), "cpu");
  const auto automatic = make_tet_stretch_evaluator(Device::Auto);
  if (cl::Runtime::available()) {
    EXPECT_EQ(automatic->name(), "opencl");
    EXPECT_EQ(make_tet_stretch_evaluator(Device::OpenCL)->name(), "opencl");
  } else {
    EXPECT_EQ(automatic->name(), "cpu");
    EXPECT_THROW(make_tet_stretch_evaluator(Device::OpenCL), DeviceError);
  }
}

}  // namespace
}  // namespace mq
