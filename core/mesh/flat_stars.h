// Vertices whose star (the faces around them) projects one-to-one onto a plane: two faces of
// such a star that share only the vertex meet nowhere else, so the intersection test needs no
// exact test for them (issue 27: on chain mail 7.3 exact tests per face, most between faces
// round one vertex of a ring's tube; an ivy leaf's fan of 48 faces cost 2,300 per fold test).
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Per vertex, 1 when its faces form one fan (a cycle round it, or a chain for a vertex on a
// border, each face joined to the next by an edge through the vertex, consistently oriented)
// that projects one-to-one onto the plane normal to the fan's mean normal: every face's sector
// at the vertex turns the same way by at least 1e-3 radians, every face within about 84 degrees
// of the mean normal, the sectors round the vertex once (a chain with a gap of 1e-3). 0
// otherwise, and for vertices of no face or of more than 64 faces. Margins make the verdict
// hold for the floating-point face test too.
//   V #V by 3 finite, F #F by 3 indices into V
//   needed (optional, #V): only these vertices are judged (the others 0)
// Throws nothing (V and F are the caller's, checked there).
std::vector<char> flat_stars(const MatrixX3d& V, const MatrixX3i& F,
                             const std::vector<char>* needed = nullptr);

}  // namespace mq
