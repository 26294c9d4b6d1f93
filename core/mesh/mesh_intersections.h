// Triangle-triangle intersection and a broad-phase search for intersecting faces of a mesh:
// the check that the geometry elements of a swatch or a synthesized result do not overlap.
#pragma once

#include <utility>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Do the closed triangles (a0,a1,a2) and (b0,b1,b2) intersect (touching counts)?
// Orientation predicates in double precision (Guigue-Devillers style: sign tests only, no
// constructed intersection points), the coplanar case handled in the dominant projection
// plane. Not exact: configurations within ~1e-15 relative of touching may go either way.
// Meant for non-degenerate triangles; for a zero-area one the answer is best effort.
bool triangles_intersect(const Vector3d& a0, const Vector3d& a1, const Vector3d& a2,
                         const Vector3d& b0, const Vector3d& b1, const Vector3d& b2);

struct IntersectionOptions {
  // true: only pairs of faces in different vertex-connected components (elements) are tested.
  // false: all pairs; faces that share vertex indices are reported only when they overlap
  // beyond the shared vertex or edge (a fold-over or a duplicated face).
  bool between_components_only = true;
};

// Pairs (f, g), f < g, of faces of the mesh that intersect, sorted lexicographically.
//   V  #V by 3 positions, F  #F by 3 indices into V
// Broad phase: a uniform grid over face bounding boxes, about O(#F) for well-distributed faces;
// parallel (TBB), output independent of the thread count.
// Throws InvalidInput for an out-of-range index or a non-finite coordinate.
std::vector<std::pair<int, int>> intersecting_face_pairs(const MatrixX3d& V, const MatrixX3i& F,
                                                         const IntersectionOptions& options = {});

// The intersecting pairs of faces with different labels (#F labels, >= 0: the piece of each
// face, say), each pair (f, g), f < g, sorted; faces of one label are not tested against each
// other. Throws like intersecting_face_pairs, and InvalidInput for #labels != #F.
std::vector<std::pair<int, int>> intersecting_face_pairs_between(const MatrixX3d& V,
                                                                 const MatrixX3i& F,
                                                                 const std::vector<int>& label);

// The pairs of intersecting_face_pairs with between_components_only = false that hold at least
// one face with active[f] != 0 (#F flags), at a cost in proportion to the active faces' share
// of the narrow phase: for re-testing after a few faces moved. Same order and throws.
std::vector<std::pair<int, int>> intersecting_face_pairs_touching(const MatrixX3d& V,
                                                                  const MatrixX3i& F,
                                                                  const std::vector<char>& active);

// The same, for labelled faces (#F labels, e.g. the element of each face): only pairs of faces
// of different labels (same_label false: elements meeting each other) or of one label (true:
// an element through itself, beyond shared vertices and edges). Same order and throws.
std::vector<std::pair<int, int>> intersecting_face_pairs_touching(const MatrixX3d& V,
                                                                  const MatrixX3i& F,
                                                                  const std::vector<char>& active,
                                                                  const std::vector<int>& label,
                                                                  bool same_label);

// The vertex-connected components (elements, numbered as connected_components numbers them)
// that intersect themselves: two of their faces overlap beyond a shared vertex or edge (a
// fold, a tube pressed through itself). Ascending. Throws like intersecting_face_pairs.
std::vector<int> self_intersecting_components(const MatrixX3d& V, const MatrixX3i& F);

// Whether any component intersects itself (!self_intersecting_components(V, F).empty()), found
// with an early stop. witness (optional): a pair (f, g), f < g, that intersected in an earlier
// shape of the same faces F is tested first, so a shape that changes little is judged by one
// triangle test (the fold repair's blends towards the flat shape); receives the pair found.
// Throws like intersecting_face_pairs.
bool self_intersects(const MatrixX3d& V, const MatrixX3i& F,
                     std::pair<int, int>* witness = nullptr);

// Does any triangle of A intersect any triangle of B? Throws like intersecting_face_pairs.
bool meshes_intersect(const TriMesh& A, const TriMesh& B);

}  // namespace mq
