#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "core/mesh/similarity_fit.h"
#include "tests/test_support.h"

namespace mq {
namespace {

MatrixX3d random_points(int n, std::mt19937_64& rng) {
  MatrixX3d P(n, 3);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) P(i, c) = test::uniform(rng, -1, 1);
  return P;
}

double signed_volume(const MatrixX3d& P) {  // of the first four points
  return (P.row(1) - P.row(0)).cross(P.row(2) - P.row(0)).dot(P.row(3) - P.row(0));
}

TEST(SimilarityFit, RecoversAScaledRotatedMovedCopy) {
  std::mt19937_64 rng(7);
  const MatrixX3d from = random_points(50, rng);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  MatrixX3d to(from.rows(), 3);
  for (Eigen::Index i = 0; i < from.rows(); ++i)
    to.row(i) = (2.5 * R * from.row(i).transpose() + Vector3d(3, -1, 4)).transpose();
  EXPECT_LT((similarity_fit(from, to) - to).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(SimilarityFit, NeverMirrors) {
  std::mt19937_64 rng(8);
  const MatrixX3d from = random_points(20, rng);
  MatrixX3d mirror = from;
  mirror.col(0) *= -1;
  const MatrixX3d fit = similarity_fit(from, mirror);
  EXPECT_GT(signed_volume(fit) * signed_volume(from), 0);  // a rotation, not a reflection
  EXPECT_GT((fit - mirror).cwiseAbs().maxCoeff(), 1e-3);   // so the mirror is not reached
}

TEST(SimilarityFit, PointsAtOnePlaceGoToTheTargetsCentroid) {
  MatrixX3d from = MatrixX3d::Constant(3, 3, 2.0), to(3, 3);
  to << 0, 0, 0, 3, 0, 0, 0, 3, 0;
  const MatrixX3d fit = similarity_fit(from, to);
  for (Eigen::Index i = 0; i < 3; ++i)
    EXPECT_LT((fit.row(i) - Eigen::RowVector3d(1, 1, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace mq
