// Element merging, paper section 2.7: the rules that decide, for a related output/swatch element
// pair, which one survives, and the cut-and-stitch that joins the two into one element.
#pragma once

#include <optional>

#include "core/mesh/embree_device.h"
#include "core/planar/overlap_region.h"
#include "core/planar/quilt_elements.h"

namespace mq {

struct MergeOptions {
  double mu = 1.0;  // Eq. (5) weight of the stitching constraints
  // Two elements closer than this many swatch mean edge lengths everywhere (both ways) are the
  // same element placed twice: the output one is kept and no cut is made.
  double coincidence_tolerance = 0.05;
  // Partners whose footprints overlap over at least this fraction of the larger one are also the
  // same element (for compact elements a stitch of two halves would only deform them).
  double same_element_overlap = 0.5;
  // A face counts as having a partner on the other element when its centroid lies within this
  // many mean edge lengths of it (the "corresponding" faces of section 2.7's SINK rule).
  double cover_distance = 2.0;
  // Seam loops whose centroids are farther apart than this many mean edge lengths are not
  // bridged (the stitch is refused and the caller keeps the output element).
  double max_loop_distance = 6.0;
  // The stitching deformation is confined to this many edge rings around the seam; vertices
  // beyond stay in place (mesh merging keeps the far parts of both elements as they were).
  int deformation_rings = 8;
  // The stitching deformation is solved over this many rings past deformation_rings, and the
  // vertices beyond keep their positions exactly (deform_locally): on the plane's weave the
  // whole-element solve moved them by at most 1e-6 mean edge lengths, at five times the cost.
  int solve_margin = 8;
  // A thread whose stitch is refused (or that has two partners) enters by its part beyond its
  // partners, capped, rather than not at all. The plane sets it: its grid marks a patch's
  // ground synthesised whatever the patch kept, so a dropped thread left a stretch without that
  // direction's threads. On a surface the ground is marked by the elements placed and a later
  // patch fills it; there the pieces cost long threads (the bunny's weave by patches: 17 -> 9
  // threads longer than the swatch's) for 0.8% of coverage.
  bool pieces_beyond = false;
};

// Every vertex of a lies within tolerance of b and every vertex of b within tolerance of a.
// device: where the temporary BVHs are built (a new device when null; creating one costs about
// as much as building a BVH over a small element).
bool elements_coincide(const Element& a, const Element& b, double tolerance,
                       const EmbreeDevice* device = nullptr);

// Why a cut-and-stitch was refused (for stats and messages).
enum class StitchFailure {
  None,
  EmptyCut,          // a cut removed a whole element
  NothingCut,        // a cut removed nothing: no seam to join
  BadSeam,           // the cut boundary is not a set of simple loops
  LoopsUnpaired,     // seam loops could not be paired within max_loop_distance
  NotOneComponent,   // the bridged result is not one connected component
  OpenSeam,          // a seam loop was left open
  Distorted,         // the deformed result left its parents' space
  SelfIntersecting,  // the deformed result passes through itself
};
inline constexpr int kStitchFailureKinds = 9;
// Short name of a failure kind, for stats.
const char* stitch_failure_name(StitchFailure f);

// Cuts the output element `out` and the swatch element `in` (already in the output frame) along
// min-cut seams (Eq. (7) weights, infinite SOURCE links outside the overlapping region, SINK
// links where a vertex's partner lies outside it or at the rim of the matched area), bridges the
// seam loops, and deforms the union with the averaged seam points as Eq. (5) constraints.
// Returns the stitched element (one connected component, no boundary edges beyond those the two
// inputs already had), or nullopt with the reason in `failure`. device: as for
// elements_coincide.
std::optional<Element> cut_and_stitch(const Element& out, const Element& in,
                                      const OverlapRegion& region, double mean_edge_length,
                                      const MergeOptions& options, StitchFailure* failure = nullptr,
                                      const EmbreeDevice* device = nullptr);

}  // namespace mq
