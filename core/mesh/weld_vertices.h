// Merging vertices that sit at exactly the same position (libigl's remove_duplicate_vertices with
// zero tolerance). Exporters split a vertex wherever its normal or texture coordinate changes,
// which cuts a closed box into separate quads: patches could not grow across its edges.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Returns mesh with every group of vertices at bitwise-equal positions (+0 and -0 equal) merged
// into the group's first vertex; faces keep their order and count, vertices keep the order of
// their first occurrence, normals (if any) are dropped when anything was merged. Unused vertices
// are kept. O(#V log #V), deterministic.
//   merged  optional output: how many vertices were removed
//   source  optional output: per vertex of the result, the vertex of `mesh` it is (the group's
//           first), so the result can follow `mesh` moved (a saved quilt re-embedded)
// Preconditions: face indices lie in [0, #V). Throws InvalidInput for a non-finite position.
TriMesh weld_vertices(const TriMesh& mesh, int* merged = nullptr,
                      std::vector<int>* source = nullptr);

}  // namespace mq
