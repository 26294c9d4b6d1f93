// Motion that keeps elements apart: an animation of a mesh whose elements (connected components)
// move over frames is damped element by element until no element meets another, or crosses
// itself, in any frame, where it did not at rest (issue 25: a swatch animation must not push a
// leaf through its neighbour). The same damping in every frame, so that a loop stays a loop.
#pragma once

#include <functional>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

struct SettledMotionStats {
  int rounds = 0;   // passes over the frames
  int damped = 0;   // elements moving at half their motion
  int stilled = 0;  // elements not moving at all
  // Elements whose motion fades where the frames would make faces meet, all alike there
  // (interlaced threads: core/shell/swatch_animation); not counted above.
  int faded = 0;
};

// Per face of F (#F), whether a corner's position in V differs from rest (both #V by 3).
std::vector<char> moved_faces(const MatrixX3d& rest, const MatrixX3d& V, const MatrixX3i& F);

// The positions of frame k (#V by 3) with each element's motion scaled by amplitude[e].
using FramePositions = std::function<MatrixX3d(int k, const std::vector<double>& amplitude)>;

// Amplitudes (per element of F as connected_components numbers them, in [0, 1]) under which no
// frame of `frames` has a pair of intersecting faces (between elements, or within one beyond shared
// vertices and edges) that `rest` does not have: 1, then 0.5, then 0 for the smaller element of
// each such pair (of fewer faces: a leaf before the stem carrying it; both when of as many faces;
// the larger once the smaller is still).
// Terminates: with every amplitude 0 each frame is rest (positions must then return rest exactly).
// The first pass tests the faces that move in each frame, later passes only the faces of elements
// just damped. Throws what intersecting_face_pairs throws.
std::vector<double> settled_amplitudes(const MatrixX3d& rest, const MatrixX3i& F, int frames,
                                       const FramePositions& positions,
                                       SettledMotionStats* stats = nullptr);

}  // namespace mq
