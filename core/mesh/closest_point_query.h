// Closest point and normal-weighted matching queries against a triangle mesh, accelerated by
// an Embree BVH. Used to measure distances between the swatch and the base surface and to
// rank candidate correspondences with the paper's distance measure (Sec. 4, Eq. (1)).
#pragma once

#include <limits>
#include <vector>

#include "core/mesh/embree_device.h"
#include "core/mesh/mesh.h"

namespace mq {

// Result of one query. face == -1 (and point/barycentric NaN, distance/cost inf) when no face
// lies within the query radius.
struct ClosestPointHit {
  int face = -1;
  // Closest point on face.
  Vector3d point = Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Weights of F(face,0..2) giving point; non-negative, sum 1.
  Vector3d barycentric = Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Euclidean distance from the query point to point.
  double distance = std::numeric_limits<double>::infinity();
  // The ranking value: distance for closest(), Eq. (1) for match().
  double cost = std::numeric_limits<double>::infinity();
};

// Precomputed BVH over a triangle mesh answering exact closest-point queries.
//
// Embree holds float copies of the positions and only prunes the search; every distance is
// computed in double from the caller's V, F (copied into the object) with
// closest_point_barycentric, so results equal a brute force over all faces. To keep float
// rounding of the BVH bounds and of the query point from pruning the exact answer, the radius
// handed to Embree is the exact bound enlarged by 1e-6 of (scene extent + largest vertex
// coordinate magnitude + query coordinate magnitude), far above float rounding (~6e-8
// relative); faces visited because of this slack are still rejected exactly in double.
//
// Single-point overloads take Vector3d and batched ones MatrixX3d: pass an Eigen expression
// such as P.row(i) as a Vector3d (or MatrixX3d) explicitly, or the call is ambiguous.
//
// Const queries are thread-safe. Non-copyable, movable; a moved-from object may only be
// destroyed or assigned to (queries on it throw InternalError).
class ClosestPointQuery {
 public:
  // V #V by 3 vertex positions, F #F by 3 vertex indices.
  // Throws InvalidInput for empty F, non-finite or float-overflowing V, out-of-range indices;
  // Error (naming the Embree error) if Embree fails.
  ClosestPointQuery(const MatrixX3d& V, const MatrixX3i& F);
  // Same, building the BVH on a shared device.
  ClosestPointQuery(const EmbreeDevice& device, const MatrixX3d& V, const MatrixX3i& F);
  ~ClosestPointQuery();
  ClosestPointQuery(const ClosestPointQuery&) = delete;
  ClosestPointQuery& operator=(const ClosestPointQuery&) = delete;
  ClosestPointQuery(ClosestPointQuery&& other) noexcept;
  ClosestPointQuery& operator=(ClosestPointQuery&& other) noexcept;

  // Closest face to p with distance <= max_radius (inclusive); ties go to the smallest face
  // index. Throws InvalidInput for non-finite p or NaN / negative max_radius.
  ClosestPointHit closest(const Vector3d& p, double max_radius = kInf) const;

  // Face minimising Eq. (1), D = (1 + lambda*dist) * (1 + |n - n_f|), over the faces within
  // max_radius (inclusive); n is normalised here, n_f is the unit face normal (zero for a
  // degenerate face). Ties go to the smallest face index. Exact: the normal factor is >= 1,
  // so a face farther than (best_D - 1)/lambda cannot win and the search radius shrinks as
  // better faces are found (lambda == 0 visits every face within max_radius).
  // Throws InvalidInput for non-finite p, zero or non-finite n, negative or non-finite lambda,
  // NaN or negative max_radius.
  ClosestPointHit match(const Vector3d& p, const Vector3d& n, double lambda = 1.0,
                        double max_radius = kInf) const;

  // Batched closest(): P #P by 3; returns #P hits in input order, computed in parallel (TBB).
  // Throws as closest() (checked for every row before any query runs).
  std::vector<ClosestPointHit> closest(const MatrixX3d& P, double max_radius = kInf) const;

  // Batched match(): P #P by 3 points, NP #P by 3 normals; returns #P hits in input order.
  // Throws as match(), and InvalidInput if NP.rows() != P.rows().
  std::vector<ClosestPointHit> match(const MatrixX3d& P, const MatrixX3d& NP, double lambda = 1.0,
                                     double max_radius = kInf) const;

  // #F by 3 unit face normals (zero rows for degenerate faces).
  const MatrixX3d& face_normals() const { return FN_; }
  int num_faces() const { return static_cast<int>(F_.rows()); }
  const MatrixX3d& vertices() const { return V_; }
  const MatrixX3i& faces() const { return F_; }
  // The device the BVH lives on, for building more queries without a new device each.
  const EmbreeDevice& device() const { return device_; }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  ClosestPointHit query(const Vector3d& p, const Vector3d* unit_n, double lambda,
                        double max_radius) const;

  EmbreeDevice device_;
  RTCScene scene_ = nullptr;
  MatrixX3d V_;
  MatrixX3i F_;
  MatrixX3d FN_;
  double scene_scale_ = 0;  // bbox diagonal + largest |coordinate|, for the pruning slack
};

// Unsigned distance from every row of P to the mesh.
//   P #P by 3 query points, V #V by 3, F #F by 3.
// Returns #P distances. Throws as ClosestPointQuery's constructor and closest().
Eigen::VectorXd point_mesh_distance(const MatrixX3d& P, const MatrixX3d& V, const MatrixX3i& F);

}  // namespace mq
