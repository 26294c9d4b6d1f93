#include "core/surface/patch_frame.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/mesh/mesh_topology.h"

namespace mq {

namespace {

// Barycentric coordinates of p's orthogonal projection onto the plane of (a, b, c); they are not
// clamped, so points beyond the triangle extrapolate its affine map.
Vector3d plane_barycentric(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                           const Vector3d& c) {
  const Vector3d e0 = b - a, e1 = c - a, d = p - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double d20 = d.dot(e0), d21 = d.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return Vector3d(1, 0, 0);
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return Vector3d(1 - v - w, v, w);
}

Vector3d triangle_barycentric_2d(const Vector2d& p, const Vector2d& a, const Vector2d& b,
                                 const Vector2d& c) {
  const Vector2d e0 = b - a, e1 = c - a, d = p - a;
  const double den = e0.x() * e1.y() - e1.x() * e0.y();
  if (!(std::abs(den) > 0)) return Vector3d(1, 0, 0);
  const double v = (d.x() * e1.y() - e1.x() * d.y()) / den;
  const double w = (e0.x() * d.y() - d.x() * e0.y()) / den;
  return Vector3d(1 - v - w, v, w);
}

}  // namespace

PatchFrame::PatchFrame(const TriMesh& base, LocalPatch patch, const Vector3d& direction,
                       const EmbreeDevice& device, double size)
    : base_(base), patch_(std::move(patch)), size_(size), device_(device) {
  const MatrixX3i& F = patch_.mesh.F;
  for (int f = 0; f < F.rows(); ++f) local_of_[patch_.faces[f]] = f;
  // The seed face's affine map takes the 3D field direction into the UV plane.
  const int s = 0;
  const Vector3d a = patch_.mesh.V.row(F(s, 0)), b = patch_.mesh.V.row(F(s, 1)),
                 c = patch_.mesh.V.row(F(s, 2));
  const Vector2d ua = patch_.uv.row(F(s, 0)), ub = patch_.uv.row(F(s, 1)),
                 uc = patch_.uv.row(F(s, 2));
  const Vector3d w = plane_barycentric(a + direction, a, b, c);
  Vector2d d = w(0) * ua + w(1) * ub + w(2) * uc - ua;
  if (!(d.norm() > 0)) d = Vector2d(1, 0);
  d.normalize();
  const Vector2d origin = (ua + ub + uc) / 3.0;
  uv_.resize(patch_.uv.rows(), 2);
  for (int v = 0; v < patch_.uv.rows(); ++v) {
    const Vector2d q = patch_.uv.row(v).transpose() - origin;
    uv_.row(v) << q.dot(d), q.x() * -d.y() + q.y() * d.x();
  }
  uv_ /= size_;
  build_grid();
}

int PatchFrame::local_face(int base_face) const {
  auto it = local_of_.find(base_face);
  return it == local_of_.end() ? -1 : it->second;
}

Vector2d PatchFrame::to_frame(int base_face, const Vector3d& bary) const {
  int f = local_face(base_face);
  Vector3d w = bary;
  if (f < 0) {
    const Vector3d p = bary(0) * base_.V.row(base_.F(base_face, 0)).transpose() +
                       bary(1) * base_.V.row(base_.F(base_face, 1)).transpose() +
                       bary(2) * base_.V.row(base_.F(base_face, 2)).transpose();
    // Built on first use: most patches never need it, and a BVH per patch is not free.
    if (!query_)
      query_ = std::make_unique<ClosestPointQuery>(device_, patch_.mesh.V, patch_.mesh.F);
    f = query_->closest(p).face;
    const MatrixX3i& F = patch_.mesh.F;
    w = plane_barycentric(p, patch_.mesh.V.row(F(f, 0)), patch_.mesh.V.row(F(f, 1)),
                          patch_.mesh.V.row(F(f, 2)));
  }
  const MatrixX3i& F = patch_.mesh.F;
  return w(0) * uv_.row(F(f, 0)).transpose() + w(1) * uv_.row(F(f, 1)).transpose() +
         w(2) * uv_.row(F(f, 2)).transpose();
}

bool PatchFrame::locate(const Vector2d& q, int& face, Vector3d& bary) const {
  const MatrixX3i& F = patch_.mesh.F;
  face = -1;
  double best = std::numeric_limits<double>::infinity();
  const int cx = std::clamp(static_cast<int>((q.x() - lo_.x()) / cell_), 0, nx_ - 1);
  const int cy = std::clamp(static_cast<int>((q.y() - lo_.y()) / cell_), 0, ny_ - 1);
  // Ring search over the grid: the first containing triangle wins; else the nearest by the
  // most negative barycentric coordinate over the rings visited.
  for (int r = 0; r < std::max(nx_, ny_); ++r) {
    for (int y = cy - r; y <= cy + r; ++y)
      for (int x = cx - r; x <= cx + r; ++x) {
        if (std::max(std::abs(x - cx), std::abs(y - cy)) != r) continue;
        if (x < 0 || y < 0 || x >= nx_ || y >= ny_) continue;
        for (const int f : cells_[y * nx_ + x]) {
          const Vector3d w =
              triangle_barycentric_2d(q, uv_.row(F(f, 0)), uv_.row(F(f, 1)), uv_.row(F(f, 2)));
          const double outside = -w.minCoeff();
          if (outside <= 1e-9) {
            face = f;
            bary = w;
            return true;
          }
          if (outside < best || (outside == best && f < face)) {
            best = outside;
            face = f;
            bary = w;
          }
        }
      }
    if (face >= 0 && r >= 1) break;
  }
  return false;
}

Vector2d PatchFrame::face_centroid(int f) const {
  const MatrixX3i& F = patch_.mesh.F;
  return (uv_.row(F(f, 0)) + uv_.row(F(f, 1)) + uv_.row(F(f, 2))).transpose() / 3.0;
}

double PatchFrame::distance_to_border(const Vector2d& q) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [i, j] : border_) {
    const Vector2d a = uv_.row(i), b = uv_.row(j), d = b - a;
    const double t =
        d.squaredNorm() > 0 ? std::clamp((q - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    best = std::min(best, (a + t * d - q).norm());
  }
  return best;
}

void PatchFrame::build_grid() {
  const MatrixX3i& F = patch_.mesh.F;
  lo_ = uv_.colwise().minCoeff().transpose();
  const Vector2d hi = uv_.colwise().maxCoeff().transpose();
  const double side = std::max((hi - lo_).maxCoeff(), 1e-12);
  const int n = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(F.rows()))));
  cell_ = side / n;
  nx_ = std::max(1, static_cast<int>((hi.x() - lo_.x()) / cell_) + 1);
  ny_ = std::max(1, static_cast<int>((hi.y() - lo_.y()) / cell_) + 1);
  cells_.assign(static_cast<size_t>(nx_) * ny_, {});
  for (int f = 0; f < F.rows(); ++f) {
    Vector2d a = uv_.row(F(f, 0)), b = a;
    for (int k = 1; k < 3; ++k) {
      a = a.cwiseMin(uv_.row(F(f, k)).transpose());
      b = b.cwiseMax(uv_.row(F(f, k)).transpose());
    }
    const int x0 = std::clamp(static_cast<int>((a.x() - lo_.x()) / cell_), 0, nx_ - 1);
    const int x1 = std::clamp(static_cast<int>((b.x() - lo_.x()) / cell_), 0, nx_ - 1);
    const int y0 = std::clamp(static_cast<int>((a.y() - lo_.y()) / cell_), 0, ny_ - 1);
    const int y1 = std::clamp(static_cast<int>((b.y() - lo_.y()) / cell_), 0, ny_ - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) cells_[y * nx_ + x].push_back(f);
  }
  const EdgeTopology topo = edge_topology(F, static_cast<int>(uv_.rows()));
  for (int e = 0; e < topo.num_edges(); ++e)
    if (topo.is_boundary(e)) border_.emplace_back(topo.E(e, 0), topo.E(e, 1));
}

}  // namespace mq
