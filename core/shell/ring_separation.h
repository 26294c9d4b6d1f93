// Separating rings that the shell map pressed into each other, without unlinking them (issue 13:
// "deformation with a collision term"). Chain mail rings are rigid in the real thing, and their
// links are a topological property of their centre loops: moving whole rings continuously,
// each step smaller than the gap between any two loops, can never pass one loop through
// another, so every link survives. Each ring is a tube of (per loop point) radius around its
// centre loop; overlapping tubes are pushed apart along their closest points by rigid motions
// (position-based rigid bodies, Jacobi iterations with averaged corrections; Mueller et al.,
// "Detailed rigid body simulation with extended position based dynamics", 2020), and a ring
// whose links changed after all is put back where it was.
//
// Beyond the paper, whose elements near a seam are deformed towards their partners: on a
// curved base the map compresses a ring's neighbourhood on the concave side and over cones of
// the parameterisation, and the post-processing then removed every ring touching another
// (armor job: 4,522 face pairs between 2,049 rings; removing them cost 9% of the rings with
// the swatch's 4 links).
#pragma once

#include <optional>
#include <vector>

#include "core/mesh/linking_number.h"
#include "core/mesh/mesh.h"
#include "core/shell/signed_height.h"

namespace mq {

struct RingSeparationOptions {
  int max_iterations = 60;
  // Gap wanted between two tubes, in wire radii (the mean of the two rings'): some room for
  // the tube model's error against the real triangles.
  double clearance = 0.3;
  // Largest move of any point of a ring's centre loop per iteration, in wire radii: small
  // enough that no loop passes through another in one step.
  double max_step = 0.2;
  // Largest distance any point of a ring's centre loop may end from where it started, in wire
  // radii: the mail stays where the map put it, and the pairs that can meet are known at the
  // start (so are all links that could change).
  double max_travel = 2.0;
  // The base surface, if given: a movable ring's tube may not sink into it (each loop point
  // stays its tube's radius above it), a static obstacle like a fixed ring. Without it, rings
  // pushed apart over a concave crease went into the base (armor job: 248 of 294 moved).
  const SignedHeight* ground = nullptr;

  // Throws InvalidInput unless max_iterations, clearance and max_travel are >= 0 and max_step
  // > 0, all finite.
  void validate() const;
};

struct RingSeparationStats {
  int rings = 0;     // rings taken into account (movable ones and their neighbours)
  int moved = 0;     // rings left at a new place
  int reverted = 0;  // moved, then put back because a link would have changed
  int iterations = 0;
  int overlaps_before = 0;  // pairs of rings whose tubes overlap, before and after
  int overlaps_after = 0;
};

// Moves the movable rings rigidly until no two tubes overlap (or max_iterations), keeping every
// pair's linking.
//   V        every element's vertices: element k's are rows first[k] .. first[k+1]-1; the rows
//            of moved rings are overwritten
//   first    #elements + 1 ascending offsets into V
//   bins     per element, its centre loop binning (ring_loop_bins; on the ring's flat shape, so
//            that a ring the map bent keeps its cross sections together), or nothing: not a
//            ring, neither moved nor looked at
//   link_bins  per element with bins, the binning links are judged by (ring_loop_bins of its
//            current positions, as measure_structure bins it): no pair's linking number by these
//            loops changes
//   movable  per element: may move; rings that may not are obstacles
// Returns per element whether it moved. Deterministic whatever the thread count. Throws
// InvalidInput when the sizes do not agree or options.validate() does.
std::vector<char> separate_rings(MatrixX3d& V, const std::vector<Eigen::Index>& first,
                                 const std::vector<std::optional<RingBins>>& bins,
                                 const std::vector<std::optional<RingBins>>& link_bins,
                                 const std::vector<char>& movable,
                                 const RingSeparationOptions& options = {},
                                 RingSeparationStats* stats = nullptr);

}  // namespace mq
