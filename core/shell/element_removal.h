// Post-processing of the embedding (issue 13: no folded or colliding element reaches the
// output): which elements go, and the two ways an element about to go is kept instead.
#pragma once

#include <utility>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/surface/surface_quilting.h"

namespace mq {

// From the intersecting face pairs of the embedded quilt (quilt_intersections.h): an element
// with a pair of its own folds through itself and goes (folded[k] and drop[k] set); of elements
// that touch each other as few as can go (greedy_vertex_cover). Over the knight (armor job,
// before ring separation) this kept 4 links on 80.4% of interior rings where dropping the later
// of each pair kept 78.0%.
//   element_of  #F: the element of each face; drop, folded: #elements flags, set here (flags
//               already set stay set)
void choose_removals(const std::vector<std::pair<int, int>>& pairs,
                     const std::vector<int>& element_of, std::vector<char>& drop,
                     std::vector<char>& folded);

// Elements dropped for touching a neighbour that have a version placed through the layout
// (rows alternative_first[k]..alternative_first[k + 1] of A; SurfaceElement::through_layout)
// take it when it clears every kept element and does not fold: an even copy of an element
// pressed into its neighbours (around a cone, where the layout's spacing is smaller than the
// element) gives way to the layout's own, distorted but threaded through its neighbours as the
// lattice is. Elements flagged in `skip` stay out.
//   first  #elements + 1 offsets of each element's rows in V (#V by 3)
// Returns #elements flags: the elements that came back (their rows of V replaced, drop cleared).
std::vector<char> try_layout_versions(const SurfaceQuilt& quilt,
                                      const std::vector<Eigen::Index>& first,
                                      const std::vector<char>& skip, const MatrixX3d& A,
                                      const std::vector<Eigen::Index>& alternative_first,
                                      MatrixX3d& V, std::vector<char>& drop);

// Elements dropped for touching a neighbour are tried again at 95%, 90%, 85% of their size about
// their centres (chain mail has clearance between linked rings: a ring pushed into its neighbour
// over a crease usually clears it at 90% of its size and still threads it). A kept shrunken
// element overwrites its rows of V and its drop flag; elements with skip[k] set are not tried.
// Neighbours are found through an ElementGrid, so this is linear in the number of elements.
// Returns how many elements came back.
int shrink_to_fit(const SurfaceQuilt& quilt, const std::vector<Eigen::Index>& first,
                  const std::vector<char>& skip, MatrixX3d& V, std::vector<char>& drop);

}  // namespace mq
