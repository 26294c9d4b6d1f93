#include "core/shell/signed_height.h"

#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

SignedHeight::SignedHeight(const MatrixX3d& V, const MatrixX3i& F) : query_(V, F) {
  const MatrixX3d& FN = query_.face_normals();  // unit, zero for degenerate faces
  vertex_normal_ = MatrixX3d::Zero(V.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Vector3d p = V.row(F(f, k)).transpose();
      const Vector3d a = V.row(F(f, (k + 1) % 3)).transpose() - p;
      const Vector3d b = V.row(F(f, (k + 2) % 3)).transpose() - p;
      const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
      vertex_normal_.row(F(f, k)) += angle * FN.row(f);
    }
  const EdgeTopology topo = edge_topology(F, static_cast<int>(V.rows()));
  MatrixX3d E = MatrixX3d::Zero(topo.num_edges(), 3);
  for (int e = 0; e < topo.num_edges(); ++e)
    for (const int* f = topo.edge_faces.begin(e); f != topo.edge_faces.end(e); ++f)
      E.row(e) += FN.row(*f);
  for (int k = 0; k < 3; ++k) {
    edge_normal_[k].resize(F.rows(), 3);
    for (Eigen::Index f = 0; f < F.rows(); ++f) edge_normal_[k].row(f) = E.row(topo.FE(f, k));
  }
}

int SignedHeight::side(const Vector3d& p, const ClosestPointHit& hit) const {
  if (hit.face < 0) return 0;
  const Vector3d& w = hit.barycentric;
  // The closest-point routine returns exact zeros outside the face's interior region: one zero
  // is an edge (the one opposite that corner), two a vertex.
  int zeros = 0, zero = -1, nonzero = -1;
  for (int k = 0; k < 3; ++k) {
    if (w(k) == 0.0) {
      ++zeros;
      zero = k;
    } else {
      nonzero = k;
    }
  }
  Vector3d n;
  if (zeros == 0)
    n = query_.face_normals().row(hit.face).transpose();
  else if (zeros == 1)
    n = edge_normal_[(zero + 1) % 3].row(hit.face).transpose();
  else
    n = vertex_normal_.row(query_.faces()(hit.face, nonzero)).transpose();
  const double s = (p - hit.point).dot(n);
  return s > 0 ? 1 : s < 0 ? -1 : 0;
}

double SignedHeight::operator()(const Vector3d& p, ClosestPointHit* hit_out) const {
  const ClosestPointHit hit = query_.closest(p);
  if (hit_out) *hit_out = hit;
  if (!(hit.distance > 0)) return 0.0;
  // Exactly in the pseudo-normal's plane (beyond an open boundary, say): not below.
  return side(p, hit) < 0 ? -hit.distance : hit.distance;
}

}  // namespace mq
