// Prism coordinates: a point of the shell as (base face, barycentric coordinates, height) in the
// prism the face sweeps along its vertices' normals (paper section 3.2: the shell space over
// the base). The same coordinates on the base moved give the point moved with it, turned with
// the surface; a saved quilt keeps its output this way (issue 25).
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Per point: its face, the barycentric coordinates b0, b1 of the face's first two corners
// (b2 = 1 - b0 - b1; slightly outside [0, 1] where the point is past the face's edge) and its
// height t along the interpolated normal, in units of the shell height H.
struct PrismCoordinates {
  std::vector<int> face;  // #P
  MatrixX3d bt;           // #P by 3: b0, b1, t
  int size() const { return static_cast<int>(face.size()); }
};

// The point with coordinates (face, b0, b1, t) over the base (V, F) with unit vertex normals N:
// sum_i b_i (V_i + t H N_i). Preconditions: indices in range.
Vector3d prism_point(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N, double H, int face,
                     const Vector3d& bt);

// The coordinates of each row of P over the base (V, F, N): from the closest point on the base,
// Newton's method on the closest face (8 steps at most). A point it cannot place exactly
// (residual over 1e-9 of H: beyond a fold of the prisms) keeps the closest point's coordinates
// and its height along the face normal; `inexact` counts them. TBB over points, each writing its
// own row: independent of the thread count. Throws InvalidInput for an empty base, H <= 0.
PrismCoordinates locate_in_prisms(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N,
                                  double H, const MatrixX3d& P, int* inexact = nullptr);

}  // namespace mq
