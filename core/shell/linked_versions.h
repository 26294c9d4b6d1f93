// Which of a ring's two placements keeps its links (issue 23). Where the layout distorts an
// element (around a cone of the parameterisation, over a crease) the global layout places an even
// copy of it, bent only by the surface, and keeps the layout's own version beside it
// (SurfaceElement::through_layout). The copy keeps the ring's shape but not always its place
// among neighbours laid out through the layout: around a cone the lattice turns under it, and a
// copy's wire misses the rings it should thread (bunny: 244 of its 324 rings without their links
// lie within 2.5 ring sizes of one of its 16 cones). This step measures both: a ring takes the
// layout's version where that one threads more of its neighbours and is still a ring (not
// folded, its hole open), else keeps the copy.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"
#include "core/surface/surface_quilting.h"

namespace mq {

struct LinkedVersionOptions {
  // A version folded more than this (radians: the angle between its halves' planes, beyond the
  // flat element's own; linking_number.h's RingShape::fold) is no ring: the structure measure's
  // limit, so that no ring is taken that the measure would count as a miss.
  double max_fold = 0.25 * 3.14159265358979323846;
  // The layout's version's centre loop may be at most max_growth times longer and
  // max_shrinkage times shorter than the copy's (whose size is the element's, clamped as
  // place_linear clamps it): a ring is not kept linked at the cost of its size. Measured
  // (Spot, bunny, cup, knight): up to 1.2 longer no base's largest or 99th-percentile ring grew;
  // at 1.3 the largest grew on all four (Spot 1.66 -> 1.78, bunny 1.73 -> 1.84).
  double max_growth = 1.2, max_shrinkage = 1.25;
  // Passes over the rings: a ring's choice changes its neighbours' links, so a second pass lets
  // a neighbour follow (rings chosen in one pass are judged against the others as they stood).
  int passes = 2;

  // Throws InvalidInput unless max_fold is in (0, pi], max_growth and max_shrinkage >= 1 and
  // passes >= 0.
  void validate() const;
};

struct LinkedVersionStats {
  int candidates = 0;  // rings with both versions
  int chosen = 0;      // rings that took the layout's version
  int links_gained = 0;
};

// Swaps element k's rows of V with its rows of A (the layout's version, rows
// alternative_first[k] .. alternative_first[k + 1] - 1) where the layout's version links more of
// the rings near it than the copy does and is itself a ring that is neither folded nor closed
// (opening at least its wire). Elements with skip[k] set, and elements that are not rings, are
// left as they are. After the call A holds, for each swapped element, its copy: the other version
// still, as element removal expects.
//   quilt   the elements (faces, flat shapes); first: #elements + 1 offsets into V (#V by 3)
// Returns #elements flags: the swapped elements. Deterministic whatever the thread count
// (each pass judges every ring against the positions at the pass's start). Throws InvalidInput
// when the offsets do not fit V and A, or options.validate() does.
std::vector<char> choose_linked_versions(
    const SurfaceQuilt& quilt, const std::vector<Eigen::Index>& first, MatrixX3d& V, MatrixX3d& A,
    const std::vector<Eigen::Index>& alternative_first, const std::vector<char>& skip,
    const LinkedVersionOptions& options = {}, LinkedVersionStats* stats = nullptr);

}  // namespace mq
