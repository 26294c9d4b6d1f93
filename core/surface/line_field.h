// Smooth N-direction fields on a triangle mesh (N = 1: a vector field, N = 2: a line field,
// directions up to sign), their matchings across edges and their singular vertices: what a
// field-aligned global parameterisation (core/surface/global_parameterization) is built on.
//
// Beyond the paper (section 3.1 orients each local patch by the guidance field at its seed):
// on a curved base the frames of neighbouring patches then disagree, and a lattice texture such
// as chain mail breaks along every patch seam. A global parameterisation needs a field whose
// singularities are few and mild; a line field splits the index-1 poles a vector field must
// have on a sphere into index-1/2 ones, around which a texture with a half-turn symmetry (the
// 4-in-1 sheet, a plain weave) still closes up.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

// Per-face orthonormal frames: b1 along the first edge, b2 = n x b1.
struct FaceFrames {
  MatrixX3d b1, b2, n;  // #F by 3 each
};
FaceFrames face_frames(const MatrixX3d& V, const MatrixX3i& F);

// Levi-Civita transport across interior edge e from its first face to its second
// (topo.edge_faces): an angle theta in the first face's frame corresponds to theta + result in
// the second's (the angle to the shared edge is kept).
double transport_angle(const MatrixX3d& V, const EdgeTopology& topo, const FaceFrames& frames,
                       int e);

// The angle of tangent vector d in face f's frame, and the unit vector at angle theta there.
double angle_in_frame(const Vector3d& d, const FaceFrames& frames, int f);
Vector3d direction_in_frame(double theta, const FaceFrames& frames, int f);

// A field of N-directions given by one representative unit vector per face (the others are it
// turned by multiples of 2 pi / N), with, for every interior manifold edge, the matching: the
// number of 2 pi / N turns that best relates the representative of one face, transported
// across the edge, to that of the other.
struct DirectionField {
  int N = 1;
  MatrixX3d direction;  // #F by 3 unit vectors in the face planes
  // For edge e of EdgeTopology (E(e,0) < E(e,1)) between faces edge_faces(e)[0] = f and [1] = g:
  // the representative of g is that of f transported across e and turned by
  // matching[e] * 2 pi / N, up to the smooth part of the rotation (in (-pi/N, pi/N]).
  // 0 on boundary and non-manifold edges.
  std::vector<int> matching;
  // Index of the field at each vertex, in units of 1/N turn (0: regular; boundary and
  // non-manifold vertices 0).
  std::vector<int> index;
};

struct LineFieldOptions {
  int N = 2;
  // Weight of the guidance against smoothness (per unit of face area over the mean face area;
  // smoothness is one per interior edge). Large: follow the guidance; small: smoothest field
  // with the guidance's rough orientation.
  double guidance_weight = 1.0;
  // Instead of the weighted fit: the smoothest field, turned as a whole towards the guidance.
  bool smoothest = false;
};

// The smoothest N-direction field close to `guidance` (#F by 3 tangent vectors, any length):
// minimises sum over interior edges |z_g - r_fg z_f|^2 + w sum_f (A_f / mean A) |z_f - z^_f|^2
// over the N-th power representation z = exp(i N theta) in each face's frame (r_fg: the
// transport across the edge), then normalises. Representatives are chosen along a dual spanning
// tree (breadth first from face 0 of each component) so that the matching is 0 on tree edges.
// One sparse factorisation. Throws InvalidInput for sizes that do not match, N outside [1, 4],
// a negative weight; SolverFailure when the factorisation fails.
DirectionField smooth_direction_field(const MatrixX3d& V, const MatrixX3i& F,
                                      const EdgeTopology& topo, const MatrixX3i& TT,
                                      const MatrixX3d& guidance,
                                      const LineFieldOptions& options = {});

// Matchings and vertex indices of a given N-direction field (representatives as they are).
DirectionField direction_field_matching(const MatrixX3d& V, const MatrixX3i& F,
                                        const EdgeTopology& topo, const MatrixX3d& direction,
                                        int N);

// Cancels singularities of opposite index at the two ends of one edge (a + and a - half-turn
// cone side by side: on a coarse base, the tip of a thin spike and its foot). The field is
// unchanged; the edge's matching takes the other turn, so that the rotation across it is no
// longer the smallest but both ends are regular: no cone and no cut where a texture element
// is larger than the spike. Returns the pairs cancelled. field: from direction_field_matching
// or smooth_direction_field on (V, F, topo).
int cancel_singular_pairs(const MatrixX3d& V, const MatrixX3i& F, const EdgeTopology& topo,
                          DirectionField& field);

}  // namespace mq
