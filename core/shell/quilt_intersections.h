// The intersecting face pairs of an embedded quilt (within an element: a fold; between two: a
// collision), found once and kept up to date as the embedding's repairs move elements.
#pragma once

#include <utility>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Every intersecting face pair of (V, F), within an element and between two, sorted.
// V #V by 3, F #F by 3. Throws like intersecting_face_pairs.
std::vector<std::pair<int, int>> all_face_pairs(const MatrixX3d& V, const MatrixX3i& F);

// The pairs all_face_pairs(V, F) would give after the elements with changed[k] set moved, from
// `pairs` found before they did: the pairs of unchanged elements stay, those of changed elements
// are found again among the faces of the elements whose boxes meet theirs. The same sorted pairs
// as a full pass, for the cost of the changed elements' neighbourhoods (the fold repair moves 274
// of the armor's 1,944 rings; a full pass over its 2.2M faces took ~1 s).
//   first       #elements + 1 offsets of each element's rows in V
//   element_of  #F: the element of each face
//   changed     #elements flags
std::vector<std::pair<int, int>> updated_face_pairs(const MatrixX3d& V, const MatrixX3i& F,
                                                    const std::vector<Eigen::Index>& first,
                                                    const std::vector<int>& element_of,
                                                    std::vector<std::pair<int, int>> pairs,
                                                    const std::vector<char>& changed);

}  // namespace mq
