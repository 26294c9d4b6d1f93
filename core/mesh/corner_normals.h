// Per-corner normals for smooth shading that keeps sharp edges sharp: a corner's normal
// averages the faces around its vertex that bend less than a crease angle from its own face.
// A smooth element (a ring, a leaf's blade) gets one normal per vertex; a thread's flat end
// cap keeps its own normal at the rim. Used by the OBJ (vn) and glTF (NORMAL) writers.
#pragma once

#include "core/mesh/mesh.h"

namespace mq {

struct CornerNormals {
  MatrixX3d N;   // #N by 3 unit normals, each distinct at its vertex
  MatrixX3i FN;  // #F by 3 indices into N: the normal of corner k of face f
};

// Normals of the corners of F.
//   V  #V by 3, F  #F by 3
//   crease_degrees  in [0, 180]: faces bending more than this from a corner's face are left out
//                   of its average (180: one area-weighted normal per vertex)
// A corner whose faces have no area gets the vertex's average, or +z if that has none either.
// Deterministic: the same input gives the same bytes whatever the thread count.
// Throws InvalidInput for a crease angle outside [0, 180] or a face index out of range.
CornerNormals corner_normals(const MatrixX3d& V, const MatrixX3i& F, double crease_degrees);

}  // namespace mq
