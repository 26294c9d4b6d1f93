#include "core/mesh/geometry_measures.h"

#include <cmath>

namespace mq {

namespace {
Vector3d face_cross(const MatrixX3d& V, const MatrixX3i& F, int f) {
  const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  return (b - a).cross(c - a);
}
}  // namespace

MatrixX3d face_normals(const MatrixX3d& V, const MatrixX3i& F) {
  MatrixX3d N(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    const Vector3d n = face_cross(V, F, f);
    const double len = n.norm();
    N.row(f) = len > 0.0 ? Vector3d(n / len) : Vector3d::Zero();
  }
  return N;
}

MatrixX3d vertex_normals(const MatrixX3d& V, const MatrixX3i& F) {
  MatrixX3d N = MatrixX3d::Zero(V.rows(), 3);
  // Summing the unnormalised cross products weights each face by twice its area.
  for (int f = 0; f < F.rows(); ++f) {
    const Vector3d n = face_cross(V, F, f);
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += n;
  }
  for (int v = 0; v < N.rows(); ++v) {
    const double len = N.row(v).norm();
    if (len > 0.0) N.row(v) /= len;
  }
  return N;
}

Eigen::VectorXd face_areas(const MatrixX3d& V, const MatrixX3i& F) {
  Eigen::VectorXd A(F.rows());
  for (int f = 0; f < F.rows(); ++f) A(f) = 0.5 * face_cross(V, F, f).norm();
  return A;
}

double surface_area(const MatrixX3d& V, const MatrixX3i& F) { return face_areas(V, F).sum(); }

BoundingBox bounding_box(const MatrixX3d& V, const MatrixX3i& F) {
  if (F.rows() == 0) return bounding_box(V);
  BoundingBox box;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) box.extend(V.row(F(f, k)).transpose());
  return box;
}

BoundingBox bounding_box(const MatrixX3d& V) {
  BoundingBox box;
  for (int v = 0; v < V.rows(); ++v) box.extend(V.row(v).transpose());
  return box;
}

double mean_edge_length(const MatrixX3d& V, const MatrixX3i& F) {
  if (F.rows() == 0) return 0.0;
  double sum = 0.0;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) sum += (V.row(F(f, k)) - V.row(F(f, (k + 1) % 3))).norm();
  return sum / (3.0 * static_cast<double>(F.rows()));
}

}  // namespace mq
