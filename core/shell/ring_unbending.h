// Rings hung over an edge instead of folded round it (issue 23: "at sharp creases ... and parts
// narrower than an element, elements bend over the edge ... no melted, hooked rings"). The shell
// map bends every element with the surface; over an edge sharper than a ring can follow (the
// rim of the bunny's ear, the knight's spikes and plate edges) a ring is folded into a C whose
// halves turn more than the structure measure's limit (kFoldLimit) against each other, a
// degenerate ring that links nothing. A real ring is rigid and hangs over such an edge, the edge
// through its hole: each folded ring is blended towards its flat shape moved rigidly to where it
// lies (blend_towards_flat, the fold repair's step), the least blend that brings its fold within
// the limit, provided it stays whole, out of the base, and keeps the linking number with every
// ring near it; where no blend does, the least that keeps half its links and makes none
// (hung_links_hold).
#pragma once

#include <optional>
#include <vector>

#include "core/mesh/linking_number.h"
#include "core/mesh/mesh.h"
#include "core/shell/placement_check.h"
#include "core/shell/signed_height.h"

namespace mq {

struct RingUnbendingOptions {
  // The fold (RingShape::fold beyond the flat shape's own, radians) a ring is brought within:
  // some way inside the structure measure's limit (kFoldLimit), so that a ring left near it is
  // not judged folded by the measure's own binning of the output.
  double target_fold = 0.8 * (M_PI / 3);
  // Shares of the placed (bent) shape tried, in order; the rest is the rigid flat shape.
  std::vector<double> keep = {0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0};
  int loop_bins = 32;  // centre loop points, as the structure measure bins rings
  // Where no blend keeps every linking number, the share of its links (neighbours whose linking
  // number with it is not 0) a hung ring must keep, making no new one. A folded ring links
  // nothing in the structure measure, so hung with half of them it holds its place in the mail;
  // over a spike its flat shape often slips off a neighbour it was folded round (armor job: 25
  // of 39 folded rings changed a link at every blend when all had to stay). 1: every link kept
  // (a flipped sign aside).
  double kept_links = 0.5;

  // Throws InvalidInput unless target_fold is in (0, pi], every keep in [0, 1) and kept_links
  // in [0, 1].
  void validate() const;
};

// The rule a hung ring's links follow: its linking numbers with its neighbours as placed and as
// hung (same order) make no new link (hung non-zero where placed is 0) and keep at least
// kept_links of the placed ones that are not 0 (a sign that flips still links). Throws
// InvalidInput when the sizes differ.
bool hung_links_hold(const std::vector<int>& placed, const std::vector<int>& hung,
                     double kept_links);

struct RingUnbendingStats {
  int folded = 0;         // rings found folded beyond the limit
  int unbent = 0;         // of them, hung rigidly enough
  int into_base = 0;      // no blend within the limit stayed out of the base
  int links_changed = 0;  // every blend within the limit made a link or lost too many
  int self_crossing = 0;  // every blend within the limit intersected itself
};

// Unbends the folded rings among the elements (element k's vertices are the rows [first[k],
// first[k + 1]) of V, its faces F[k] indexing them, its flat shape flat[k] (#V_k by 3, the swatch
// element as the layout placed it; nullptr or a row count other than V_k's: not a candidate)).
// Elements with skip[k] set are neither moved nor looked at as neighbours. A candidate is a ring
// (ring_loop_bins of its flat shape) whose fold exceeds its flat shape's by more than kFoldLimit;
// its neighbours are the ring-shaped elements whose boxes meet its own. Candidates are unbent
// against their neighbours as placed, then, in element order, one whose linking with an
// already unbent neighbour changed is put back: deterministic whatever the thread count.
//   ground  the base, if given: an unbent ring must keep every vertex above it (check)
//   only     if given (#elements flags): only these may be unbent (the others are still
//            neighbours), for a second pass over the rings whose neighbourhood changed
// Returns per element whether it moved. Throws InvalidInput when the sizes disagree or the
// options are invalid.
std::vector<char> unbend_folded_rings(MatrixX3d& V, const std::vector<Eigen::Index>& first,
                                      const std::vector<const MatrixX3i*>& F,
                                      const std::vector<const MatrixX3d*>& flat,
                                      const std::vector<char>& skip, const SignedHeight* ground,
                                      const PlacementCheckOptions& check,
                                      const RingUnbendingOptions& options = {},
                                      RingUnbendingStats* stats = nullptr,
                                      const std::vector<char>* only = nullptr);

}  // namespace mq
