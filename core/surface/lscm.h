// Least-squares conformal map (Levy et al. 2002) of a disk-topology triangle patch: the planar
// parameterisation used to flatten local base-mesh patches in mesh quilting over curved surfaces
// (paper section 3.1).
#pragma once

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace mq {

// Least-squares conformal map of a patch with exactly one boundary loop.
// Minimises the discrete Cauchy-Riemann residual sum_T A_T |rot90(grad u) - grad v|^2 with two
// pinned boundary vertices (deterministic: a double sweep for a far-apart pair on the boundary),
// then rescales the result so that its total area equals the total 3D area, so that the area
// distortion below is meaningful. Orientation-preserving: counter-clockwise faces map to
// positive-area UV triangles unless the map folds.
//   V  #V by 3 positions (finite); every vertex must be used by a face
//   F  #F by 3 vertex indices in [0, #V), consistently oriented
// Returns UV, #V by 2. One sparse factorisation.
// Throws InvalidInput for empty F, an index out of range, a non-finite position, an unused
// vertex, a face with a repeated vertex or zero area; TopologyError when the patch is not a
// topological disk (non-manifold edge or vertex, no boundary, several boundary loops, several
// components, Euler characteristic != 1); SolverFailure when the solve fails.
MatrixX2d lscm(const MatrixX3d& V, const MatrixX3i& F);

// Per-face area distortion max(a_uv / a_3d, a_3d / a_uv) with unsigned areas (1 for an isometry
// up to the global scale fixed by lscm); +inf for a face with zero area in either domain. The
// paper shrinks a patch whose worst value exceeds 4.
//   V #V by 3, F #F by 3, UV #V by 2
// Returns #F. Throws InvalidInput on a size mismatch or an index out of range.
Eigen::VectorXd face_area_distortion(const MatrixX3d& V, const MatrixX3i& F, const MatrixX2d& UV);

// Number of UV triangles with negative signed area (flipped relative to counter-clockwise).
//   F #F by 3, UV #V by 2
// Throws InvalidInput for an index out of range.
int count_flipped(const MatrixX3i& F, const MatrixX2d& UV);

}  // namespace mq
