// Ordered boundary loops of a triangle mesh.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// The boundary loops of F, each an ordered list of vertex indices. A loop follows the faces'
// orientation: consecutive entries (loop[i], loop[i+1]) (cyclically) are a boundary edge
// traversed as in its face, so the surface lies to the left of the loop seen from the side
// the face normals point to. Edges used by exactly one face are boundary edges.
// Deterministic: each loop starts at its smallest vertex index; loops are sorted by it.
//   F             #F by 3 vertex indices
//   num_vertices  number of vertices (indices of F lie in [0, num_vertices))
// Throws InvalidInput for an out-of-range index; TopologyError when a vertex has more than one
// outgoing or incoming boundary edge, or unequal counts (a non-manifold boundary vertex or
// inconsistent face orientation), or when an edge is used by more than two faces.
std::vector<std::vector<int>> boundary_loops(const MatrixX3i& F, int num_vertices);

}  // namespace mq
