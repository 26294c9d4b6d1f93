#include "core/mesh/similarity_fit.h"

#include <Eigen/SVD>

namespace mq {

MatrixX3d similarity_fit(const MatrixX3d& from, const MatrixX3d& to) {
  const Vector3d cf = from.colwise().mean().transpose(), ct = to.colwise().mean().transpose();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var = 0;
  for (Eigen::Index i = 0; i < from.rows(); ++i) {
    const Vector3d a = from.row(i).transpose() - cf, b = to.row(i).transpose() - ct;
    cov += b * a.transpose();
    var += a.squaredNorm();
  }
  Vector3d singular;
  const Eigen::Matrix3d R = nearest_rotation(cov, &singular);
  const double scale = var > 0 ? singular.sum() / var : 1.0;
  MatrixX3d out(from.rows(), 3);
  for (Eigen::Index i = 0; i < from.rows(); ++i)
    out.row(i) = (ct + scale * R * (from.row(i).transpose() - cf)).transpose();
  return out;
}

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& cross_covariance, Vector3d* singular) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross_covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) S(2, 2) = -1;
  if (singular) *singular = (svd.singularValues().asDiagonal() * S).diagonal();
  return svd.matrixU() * S * svd.matrixV().transpose();
}

}  // namespace mq
