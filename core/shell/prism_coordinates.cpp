#include "core/shell/prism_coordinates.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"

namespace mq {

Vector3d prism_point(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N, int face,
                     const Vector3d& b, double h) {
  Vector3d p = Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const int v = F(face, k);
    p += b(k) * (V.row(v).transpose() + h * N.row(v).transpose());
  }
  return p;
}

LocalCoordinates locate_in_prisms(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N,
                                  double H, const MatrixX3d& P, int* inexact) {
  MQ_CHECK(F.rows() > 0, InvalidInput, "locate_in_prisms: empty base");
  MQ_CHECK(std::isfinite(H) && H > 0, InvalidInput, "locate_in_prisms: shell height ", H);
  const ClosestPointQuery query(V, F);
  LocalCoordinates out;
  out.face.resize(P.rows());
  out.bary.resize(P.rows(), 3);
  out.height.resize(P.rows());
  std::atomic<int> failed{0};
  tbb::parallel_for(Eigen::Index{0}, P.rows(), [&](Eigen::Index i) {
    const Vector3d p = P.row(i).transpose();
    const ClosestPointHit hit = query.closest(p);
    const int f = hit.face;
    const Vector3d n = query.face_normals().row(f).transpose();
    Vector3d x(hit.barycentric(0), hit.barycentric(1), (p - hit.point).dot(n) / H);
    const Vector3d start = x;
    const Vector3d v0 = V.row(F(f, 0)).transpose(), v1 = V.row(F(f, 1)).transpose(),
                   v2 = V.row(F(f, 2)).transpose();
    const Vector3d n0 = N.row(F(f, 0)).transpose(), n1 = N.row(F(f, 1)).transpose(),
                   n2 = N.row(F(f, 2)).transpose();
    // x = (b0, b1, t): b2 = 1 - b0 - b1, the height t H.
    auto point = [&](const Vector3d& y) {
      return prism_point(V, F, N, f, Vector3d(y(0), y(1), 1.0 - y(0) - y(1)), y(2) * H);
    };
    bool exact = false;
    for (int step = 0; step < 8; ++step) {
      const Vector3d r = point(x) - p;
      if (r.norm() <= 1e-9 * H) {
        exact = true;
        break;
      }
      Eigen::Matrix3d J;
      J.col(0) = (v0 - v2) + (x(2) * H) * (n0 - n2);
      J.col(1) = (v1 - v2) + (x(2) * H) * (n1 - n2);
      J.col(2) = H * (n2 + x(0) * (n0 - n2) + x(1) * (n1 - n2));
      const Eigen::FullPivLU<Eigen::Matrix3d> lu(J);
      if (!lu.isInvertible()) break;
      x -= lu.solve(r);
      if (!x.allFinite()) break;
    }
    if (!exact) exact = x.allFinite() && (point(x) - p).norm() <= 1e-9 * H;
    if (!exact) {
      x = start;
      failed.fetch_add(1, std::memory_order_relaxed);
    }
    out.face(i) = f;
    out.bary.row(i) << x(0), x(1), 1.0 - x(0) - x(1);
    out.height(i) = x(2) * H;
  });
  if (inexact) *inexact = failed.load();
  return out;
}

}  // namespace mq
