// Element merging, paper section 2.7: the rules that decide, for a related output/swatch element
// pair, which one survives, and the cut-and-stitch that joins the two into one element.
#pragma once

#include <optional>

#include "core/overlap_region.h"
#include "core/quilt_elements.h"

namespace mq {

struct MergeOptions {
  double mu = 1.0;  // Eq. (5) weight of the stitching constraints
  // Two elements closer than this many swatch mean edge lengths everywhere (both ways) are the
  // same element placed twice: the output one is kept and no cut is made.
  double coincidence_tolerance = 0.05;
  // A face counts as having a partner on the other element when its centroid lies within this
  // many mean edge lengths of it (the "corresponding" faces of section 2.7's SINK rule).
  double cover_distance = 1.0;
  // Seam loops whose centroids are farther apart than this many mean edge lengths are not
  // bridged (the stitch is refused and the caller keeps the output element).
  double max_loop_distance = 6.0;
};

// Every vertex of a lies within tolerance of b and every vertex of b within tolerance of a.
bool elements_coincide(const Element& a, const Element& b, double tolerance);

// Why a cut-and-stitch was refused (for stats and messages).
// NonManifoldCut: a kept part's cut boundary is non-manifold (e.g. faces meeting at one vertex),
// so its seam loops are undefined.
enum class StitchFailure {
  None,
  EmptyCut,
  NothingCut,
  NonManifoldCut,
  LoopsUnpaired,
  NotOneComponent,
  OpenSeam
};

// Cuts the output element `out` and the swatch element `in` (already in the output frame) along
// min-cut seams (Eq. (7) weights, infinite SOURCE links outside the overlapping region, SINK
// links where a vertex's partner lies outside it or at the rim of the matched area), bridges the
// seam loops, and deforms the union with the averaged seam points as Eq. (5) constraints.
// Returns the stitched element (one connected component, no boundary edges beyond those the two
// inputs already had), or nullopt with the reason in `failure`.
std::optional<Element> cut_and_stitch(const Element& out, const Element& in,
                                      const OverlapRegion& region, double mean_edge_length,
                                      const MergeOptions& options,
                                      StitchFailure* failure = nullptr);

}  // namespace mq
