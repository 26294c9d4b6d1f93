// Stretch of the shell map (paper section 3.2, Eqs. 8-9): the closed form, the reference and
// the normalisation that makes 1.0 a lower bound.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/common/errors.h"
#include "core/shell/shell_tetrahedra.h"
#include "core/shell/tet_stretch.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

using test::uniform;

// The shell of a small icosphere: a fixture with tets of many shapes.
StretchProblem sphere_shell_identity() {
  const TriMesh s = test::icosphere(2);
  const TetMesh shell = shell_tetrahedra(s.V, 1.1 * s.V, s.F);
  return {shell.V, shell.V, shell.T};
}

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  const Eigen::Quaterniond q(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1),
                             uniform(rng, -1, 1));
  return q.normalized().toRotationMatrix();
}

TEST(TetStretch, IdentityIsOneEverywhere) {
  const StretchProblem pb = sphere_shell_identity();
  TetStretchCpu cpu;
  const Eigen::VectorXd fast = cpu.per_tet(pb), ref = tet_stretch_reference(pb);
  ASSERT_EQ(fast.size(), pb.T.rows());
  EXPECT_NEAR((fast.array() - 1.0).abs().maxCoeff(), 0.0, 1e-12);
  EXPECT_NEAR((ref.array() - 1.0).abs().maxCoeff(), 0.0, 1e-12);
  EXPECT_NEAR(total_stretch(pb, fast), 1.0, 1e-12);
}

TEST(TetStretch, SimilarityIsOneAfterNormalisation) {
  std::mt19937_64 rng(7);
  StretchProblem pb = sphere_shell_identity();
  for (double s : {0.25, 2.0, 13.0}) {
    SCOPED_TRACE(s);
    const Eigen::Matrix3d R = random_rotation(rng);
    const Eigen::RowVector3d shift(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5));
    pb.texture_V = ((s * pb.shell_V * R.transpose()).rowwise() + shift).eval();
    const Eigen::VectorXd per = TetStretchCpu().per_tet(pb);
    // J = d(shell) / d(texture) = R^T / s: every tet stretches by 1/s.
    EXPECT_NEAR((per.array() - 1.0 / s).abs().maxCoeff(), 0.0, 1e-12 / s);
    EXPECT_NEAR(total_stretch(pb, per), 1.0, 1e-12);
  }
}

TEST(TetStretch, AnisotropicScaleExceedsOne) {
  StretchProblem pb = sphere_shell_identity();
  pb.texture_V.col(0) *= 2.0;
  const Eigen::VectorXd per = TetStretchCpu().per_tet(pb);
  // J = diag(1/2, 1, 1): L2 = sqrt((1/4 + 1 + 1) / 3); normalised by cbrt(V_t / V_s) = cbrt(2).
  const double l2 = std::sqrt(2.25 / 3.0);
  EXPECT_NEAR((per.array() - l2).abs().maxCoeff(), 0.0, 1e-12);
  EXPECT_NEAR(total_stretch(pb, per), l2 * std::cbrt(2.0), 1e-12);
  EXPECT_GT(total_stretch(pb, per), 1.0 + 1e-3);
}

TEST(TetStretch, OneIsALowerBoundForAnyMap) {
  // Random orientation-preserving maps: smooth global ones, per-vertex jitter, and piecewise
  // scalings that differ a lot between tets (where the paper's square-root factor fails).
  const StretchProblem base = sphere_shell_identity();
  std::mt19937_64 rng(11);
  TetStretchCpu cpu;
  int finite = 0;
  for (int trial = 0; trial < 60; ++trial) {
    StretchProblem pb = base;
    Eigen::Matrix3d A = random_rotation(rng);
    for (int a = 0; a < 3; ++a) A.row(a) *= uniform(rng, 0.2, 5.0);
    if (A.determinant() < 0) A.row(0) *= -1.0;
    pb.texture_V = (pb.shell_V * A.transpose()).eval();
    const double jitter = uniform(rng, 0.0, 0.02);
    for (Eigen::Index i = 0; i < pb.texture_V.rows(); ++i)
      for (int a = 0; a < 3; ++a) pb.texture_V(i, a) += uniform(rng, -jitter, jitter);
    const Eigen::VectorXd per = cpu.per_tet(pb);
    const double total = total_stretch(pb, per);
    if (!std::isfinite(total)) continue;  // a jittered tet folded
    ++finite;
    EXPECT_GE(total, 1.0 - 1e-12) << "trial " << trial;
  }
  EXPECT_GT(finite, 40);
  // Two disjoint tets of equal shell volume, scaled by 1 and by 0.001 into texture space.
  StretchProblem two;
  two.shell_V.resize(8, 3);
  two.shell_V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 5, 0, 0, 6, 0, 0, 5, 1, 0, 5, 0, 1;
  two.T.resize(2, 4);
  two.T << 0, 1, 2, 3, 4, 5, 6, 7;
  two.texture_V = two.shell_V;
  two.texture_V.bottomRows(4) *= 1e-3;
  const double total = total_stretch(two, cpu.per_tet(two));
  EXPECT_GE(total, 1.0);
}

TEST(TetStretch, FoldedOrFlatTextureTetIsInfinite) {
  StretchProblem pb = sphere_shell_identity();
  const int v = pb.T(0, 3);
  pb.texture_V.row(v) = pb.texture_V.row(pb.T(0, 0));  // tet 0 collapses in texture space
  const Eigen::VectorXd per = TetStretchCpu().per_tet(pb), ref = tet_stretch_reference(pb);
  EXPECT_EQ(per(0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(ref(0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(total_stretch(pb, per), std::numeric_limits<double>::infinity());
  pb = sphere_shell_identity();
  pb.texture_V.col(2) *= -1.0;  // a mirror folds every tet
  EXPECT_TRUE(
      (TetStretchCpu().per_tet(pb).array() == std::numeric_limits<double>::infinity()).all());
}

TEST(TetStretch, CpuMatchesReferenceOnPerturbedBunnyShell) {
  const test::OffsetBase ob = test::offset_base("base/bunny_igl_7k.off");
  const TetMesh shell = shell_tetrahedra(ob.base.V, ob.offset.V, ob.base.F);
  StretchProblem pb{shell.V, shell.V, shell.T};
  std::mt19937_64 rng(5);
  const double e = 0.2 * ob.options.height;
  for (Eigen::Index i = 0; i < pb.texture_V.rows(); ++i)
    for (int a = 0; a < 3; ++a) pb.texture_V(i, a) = 1.7 * pb.texture_V(i, a) + uniform(rng, -e, e);
  const Eigen::VectorXd fast = TetStretchCpu().per_tet(pb), ref = tet_stretch_reference(pb);
  int finite = 0;
  for (Eigen::Index t = 0; t < ref.size(); ++t) {
    if (std::isinf(ref(t))) {
      EXPECT_TRUE(std::isinf(fast(t)));
      continue;
    }
    ++finite;
    ASSERT_LE(std::abs(fast(t) - ref(t)), 1e-9 * ref(t)) << "tet " << t;
  }
  EXPECT_GT(finite, ref.size() / 2);
  EXPECT_TRUE(fast == TetStretchCpu().per_tet(pb));  // repeatable
}

TEST(TetStretch, InvalidInputThrows) {
  const StretchProblem good = sphere_shell_identity();
  TetStretchCpu cpu;
  StretchProblem pb = good;
  pb.texture_V = good.texture_V.topRows(5);
  EXPECT_THROW(cpu.per_tet(pb), InvalidInput);
  EXPECT_THROW(tet_stretch_reference(pb), InvalidInput);
  pb = good;
  pb.texture_V(3, 1) = std::nan("");
  EXPECT_THROW(cpu.per_tet(pb), InvalidInput);
  pb = good;
  pb.shell_V(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(cpu.per_tet(pb), InvalidInput);
  pb = good;
  pb.T(4, 2) = static_cast<int>(good.shell_V.rows());
  EXPECT_THROW(cpu.per_tet(pb), InvalidInput);
  pb.T(4, 2) = -1;
  EXPECT_THROW(tet_stretch_reference(pb), InvalidInput);
  const Eigen::VectorXd per = cpu.per_tet(good);
  EXPECT_THROW(total_stretch(good, per.head(3)), InvalidInput);
  Eigen::VectorXd nan = per;
  nan(2) = std::nan("");
  EXPECT_THROW(total_stretch(good, nan), InvalidInput);
  StretchProblem empty;
  EXPECT_EQ(cpu.per_tet(empty).size(), 0);
  EXPECT_THROW(total_stretch(empty, Eigen::VectorXd()), InvalidInput);
}

}  // namespace
}  // namespace mq
