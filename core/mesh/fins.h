// Fins: small pieces of surface sticking out of a larger one at non-manifold edges.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// The faces of the mesh's fins, ascending. Pieces are the faces joined across manifold edges
// (two faces); a piece is a fin when it meets the rest only at non-manifold edges, each of
// which keeps exactly two faces without it, both in one other piece at least
// `min_area_ratio` times its area. Without the fins those edges are manifold: the larger
// surface runs on through them. Two-sided sheets (front and back, each a piece of the same
// size) and pieces of comparable size meeting at an edge are not fins.
//   mesh                #V by 3 positions, #F by 3 faces (indices in range)
//   min_area_ratio      > 1
//   non_manifold_left   optional output: the non-manifold edges of the mesh without its fins
//                       (the edge topology is built here once; no need to build it again)
// O(#F log #F). Throws InvalidInput for indices out of range.
std::vector<int> fin_faces(const TriMesh& mesh, double min_area_ratio = 10.0,
                           int* non_manifold_left = nullptr);

}  // namespace mq
