#include "core/shell/base_fold_repair.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"
#include "core/shell/offset_surface.h"
#include "core/shell/signed_height.h"

namespace mq {

std::vector<int> folded_faces(const MatrixX3d& V, const MatrixX3i& F) {
  const int n = static_cast<int>(V.rows());
  const EdgeTopology topo = edge_topology(F, n);  // validates indices
  const MatrixX3i TT = face_adjacency(topo);
  const MatrixX3d FN = face_normals(V, F);
  const Eigen::VectorXd A = face_areas(V, F);
  const MatrixX3d VN = vertex_normals(V, F);
  std::vector<char> folded(F.rows(), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    Vector3d s = Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (TT(f, k) >= 0) s += A(TT(f, k)) * FN.row(TT(f, k)).transpose();
    if (s.dot(FN.row(f)) < 0.0) folded[f] = 1;
    for (int k = 0; k < 3; ++k)
      if (VN.row(F(f, k)).dot(FN.row(f)) < 0.0) folded[f] = 1;
  }
  std::vector<int> out;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (folded[f]) out.push_back(static_cast<int>(f));
  return out;
}

namespace {

// What is relaxed and judged: the corners of folded faces, or offset_surface's fold vertices.
std::vector<int> fold_corners(const MatrixX3d& X, const MatrixX3i& F, bool offset_criterion) {
  std::vector<int> corners;
  if (offset_criterion) {
    corners = fold_vertices(X, F);
  } else {
    for (const int f : folded_faces(X, F))
      for (int k = 0; k < 3; ++k) corners.push_back(F(f, k));
  }
  return corners;
}

// Laplacian smoothing of the vertices to relax, each move bounded: within max_shift of where it
// was and, with a base, within the band max_above / max_below around it.
class BoundedSmoothing {
 public:
  BoundedSmoothing(const MatrixX3d& V, const MatrixX3i& F, const FoldRepairOptions& options)
      : V_(V),
        options_(options),
        vv_(vertex_adjacency(F, static_cast<int>(V.rows()))),
        bounded_(std::isfinite(options.max_above) || std::isfinite(options.max_below)),
        shift_bounded_(std::isfinite(options.max_shift)) {
    if (bounded_) base_.emplace(V, F);
  }

  // The relaxed set grown by one ring (remaining always in it).
  void grow(std::vector<char>& relax, const std::vector<int>& remaining) const {
    std::vector<char> grown = relax;
    for (int i = 0; i < static_cast<int>(relax.size()); ++i)
      if (relax[i])
        for (const int* j = vv_.begin(i); j != vv_.end(i); ++j) grown[*j] = 1;
    relax.swap(grown);
    for (const int v : remaining) relax[v] = 1;
  }

  // smoothing_iterations Jacobi steps over the relaxed vertices of X.
  void smooth(MatrixX3d& X, const std::vector<char>& relax) const {
    std::vector<int> active;
    for (int i = 0; i < static_cast<int>(relax.size()); ++i)
      if (relax[i] && vv_.degree(i) > 0) active.push_back(i);
    for (int it = 0; it < options_.smoothing_iterations; ++it) {
      MatrixX3d next = X;
      tbb::parallel_for(size_t{0}, active.size(), [&](size_t a) {
        const int i = active[a];
        Vector3d c = Vector3d::Zero();
        for (const int* j = vv_.begin(i); j != vv_.end(i); ++j) c += X.row(*j).transpose();
        c /= vv_.degree(i);
        const Vector3d p0 = V_.row(i).transpose();
        if (shift_bounded_) {
          const double d = (c - p0).norm();
          if (d > options_.max_shift) c = p0 + (options_.max_shift / d) * (c - p0);
        }
        if (bounded_) c = within_bounds(c);
        // Pulled back to the base, it may have gone farther from where it was: then it stays.
        if (!shift_bounded_ || (c - p0).norm() <= options_.max_shift) next.row(i) = c.transpose();
      });
      X.swap(next);
    }
  }

  // The moved vertices, the largest move and, with a base, the largest heights above and below.
  void measure(FoldRepair& out) const {
    for (int i = 0; i < static_cast<int>(V_.rows()); ++i) {
      const double d = (out.V.row(i) - V_.row(i)).norm();
      if (d > 0.0) {
        out.moved_vertices.push_back(i);
        out.max_displacement = std::max(out.max_displacement, d);
        if (bounded_) {
          const double h = (*base_)(Vector3d(out.V.row(i).transpose()));
          out.max_above = std::max(out.max_above, h);
          out.max_below = std::max(out.max_below, -h);
        }
      }
    }
  }

 private:
  // p pulled back along its way to its closest point on the base, into the band the bounds
  // allow (the closest point stays the same along that segment, so the distance is exact).
  Vector3d within_bounds(const Vector3d& p) const {
    ClosestPointHit hit;
    const double h = (*base_)(p, &hit);
    const double limit = h > 0 ? options_.max_above : options_.max_below;
    if (std::abs(h) <= limit) return p;
    return hit.point + (limit / std::abs(h)) * (p - hit.point);
  }

  const MatrixX3d& V_;
  const FoldRepairOptions& options_;
  const Adjacency vv_;
  const bool bounded_, shift_bounded_;
  std::optional<SignedHeight> base_;
};

}  // namespace

FoldRepair repair_folds(const MatrixX3d& V, const MatrixX3i& F, const FoldRepairOptions& options) {
  MQ_CHECK(options.smoothing_iterations >= 1 && options.max_rounds >= 1, InvalidInput,
           "fold repair: smoothing_iterations and max_rounds must be >= 1");
  MQ_CHECK(options.max_above >= 0 && options.max_below >= 0 && options.max_shift >= 0, InvalidInput,
           "fold repair: max_above, max_below and max_shift must be >= 0");
  MQ_CHECK(V.allFinite(), InvalidInput, "fold repair: vertices contain NaN or infinite values");
  const int n = static_cast<int>(V.rows());
  FoldRepair out;
  out.V = V;
  out.folded_faces = folded_faces(V, F);
  std::vector<int> remaining = options.offset_criterion ? fold_vertices(V, F) : std::vector<int>();
  if (!options.offset_criterion)
    for (const int f : out.folded_faces)
      for (int k = 0; k < 3; ++k) remaining.push_back(F(f, k));
  if (remaining.empty()) return out;
  const BoundedSmoothing smoothing(V, F, options);
  std::vector<char> relax(n, 0);
  for (const int v : remaining) relax[v] = 1;
  for (int round = 0; round < options.max_rounds && !remaining.empty(); ++round) {
    if (round > 0) smoothing.grow(relax, remaining);
    smoothing.smooth(out.V, relax);
    remaining = fold_corners(out.V, F, options.offset_criterion);
  }
  if (options.offset_criterion) {
    const Adjacency vf = vertex_faces(F, n);
    for (const int v : remaining)
      out.unrepaired_faces.insert(out.unrepaired_faces.end(), vf.begin(v), vf.end(v));
    std::sort(out.unrepaired_faces.begin(), out.unrepaired_faces.end());
    out.unrepaired_faces.erase(
        std::unique(out.unrepaired_faces.begin(), out.unrepaired_faces.end()),
        out.unrepaired_faces.end());
  } else {
    out.unrepaired_faces = folded_faces(out.V, F);
  }
  smoothing.measure(out);
  return out;
}

}  // namespace mq
