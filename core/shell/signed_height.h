// Signed height of points over a base surface: the distance to the closest point on the base,
// positive on the side its faces' normals point to. The side is decided by the angle-weighted
// pseudo-normal of the feature (face, edge or vertex) the closest point lies on (Baerentzen and
// Aanaes 2005), which on a closed surface tells inside from outside exactly. Used to check
// that the texture lies over the base as given, never inside it (issue 23).
#pragma once

#include "core/mesh/closest_point_query.h"
#include "core/mesh/mesh.h"

namespace mq {

class SignedHeight {
 public:
  // V #V by 3, F #F by 3, faces counter-clockwise seen from outside; open boundaries and
  // non-manifold edges are allowed (an edge's pseudo-normal sums all its faces' normals).
  // Throws as ClosestPointQuery's constructor (InvalidInput for no faces, non-finite vertices,
  // indices out of range).
  SignedHeight(const MatrixX3d& V, const MatrixX3i& F);

  // Signed height of p: +-distance to the closest point of the base (positive when the side is
  // 0), 0 on it. `hit`, if given, receives the closest point. Thread-safe. Throws InvalidInput for
  // non-finite p.
  double operator()(const Vector3d& p, ClosestPointHit* hit = nullptr) const;

  // The closest point of the base and its pseudo-normal's side: the sign of (p - hit.point)
  // against the pseudo-normal of the feature hit.point lies on (+1, -1, or 0 on the base).
  int side(const Vector3d& p, const ClosestPointHit& hit) const;

  const ClosestPointQuery& query() const { return query_; }
  // #V by 3 angle-weighted vertex pseudo-normals (not normalised: only their direction counts).
  const MatrixX3d& vertex_normals() const { return vertex_normal_; }

 private:
  ClosestPointQuery query_;
  MatrixX3d vertex_normal_;
  MatrixX3d edge_normal_[3];  // per face, the pseudo-normal of its edge from corner k to k + 1
};

}  // namespace mq
