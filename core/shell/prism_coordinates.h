// Prism coordinates: a point of the shell in local coordinates (base face, barycentric
// coordinates, height) of the prism the face sweeps along its vertices' normals (paper section 3.2:
// the shell space over the base). The same coordinates on the base moved give the point moved with
// it, turned with the surface; a saved quilt keeps its output this way (issue 25).
#pragma once

#include "core/mesh/local_coordinates.h"
#include "core/mesh/mesh.h"

namespace mq {

// The point at local coordinates (face, b, h) in the prism over the base (V, F) with unit
// vertex normals N: sum_i b_i (V_i + h N_i). Preconditions: indices in range.
Vector3d prism_point(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N, int face,
                     const Vector3d& b, double h);

// The local coordinates of each row of P in the prisms over the base (V, F, N): from the
// closest point on the base, Newton's method on the closest face (8 steps at most). `H` is the
// shell height, the scale of the tolerance: a point it cannot place within 1e-9 H (beyond a fold
// of the prisms) keeps the closest point's coordinates and its height along the face normal;
// `inexact` counts them. TBB over points, each writing its own row: independent of the thread
// count. Throws InvalidInput for an empty base, H <= 0.
LocalCoordinates locate_in_prisms(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N,
                                  double H, const MatrixX3d& P, int* inexact = nullptr);

}  // namespace mq
