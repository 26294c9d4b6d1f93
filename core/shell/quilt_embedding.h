// The final embedding of a surface quilt (paper section 3.2): output vertices, stored in local
// coordinates over the base, are placed in 3D through the stretch-minimised shell map (default)
// or by plain normal displacement; elements that cannot be embedded whole without intersecting
// themselves or their neighbours are then removed (post-processing).
#pragma once

#include <string>
#include <vector>

#include "core/shell/tet_stretch.h"
#include "core/surface/surface_quilting.h"

namespace mq {

struct QuiltEmbeddingOptions {
  bool shell_map = true;            // false: plain normal displacement
  bool optimize_stretch = true;     // random line search on the shell map (section 3.2)
  bool remove_intersecting = true;  // post-processing
  // Before removing an element that touches a neighbour, try it at 95%, 90%, 85% of its size.
  bool shrink_to_fit = true;
  // Before removing rings that touch each other, move them apart whole
  // (core/shell/ring_separation).
  bool separate_rings = true;
  // Rings placed as even copies take the layout's version where it keeps more links
  // (core/shell/linked_versions).
  bool choose_linked_versions = true;
  // Rings folded over an edge sharper than they can follow are hung over it rigidly instead
  // (core/shell/ring_unbending).
  bool unbend_rings = true;
  std::uint64_t seed = 1;
  // Per face of quilt.base, where coverage is measured (a mask, core/surface/surface_mask);
  // empty: the whole base.
  std::vector<char> coverage_faces;
};

struct QuiltEmbeddingStats {
  double stretch_before = 0, stretch_after = 0;  // Eq. (9), 1.0 the lower bound
  int optimization_sweeps = 0;
  int atlas_charts = 0;
  int shell_smoothing_steps = 0;  // normal diffusion steps of the offset surface
  int fold_repaired_vertices = 0;
  int removed_intersecting = 0;       // intersecting another element
  int removed_self_intersecting = 0;  // folded through itself, and no repair possible
  int rigid_repairs = 0;              // folded elements replaced by their flat shape moved rigidly
  int shrunk_to_fit = 0;              // elements kept at 85-95% of their size instead of removed
  int linked_versions = 0;  // even copies replaced by the layout's version, which links more
  int layout_versions = 0;  // even copies that touched a neighbour, kept as the layout placed them
  int separated_rings = 0;  // rings moved apart from those they touched
  int folded_rings = 0;     // rings folded over an edge beyond the structure measure's limit
  int unbent_rings = 0;     // of them, hung over it rigidly enough (core/shell/ring_unbending)
  // Rings still folded after the removal (brought back there as the layout placed them, or
  // pressed into a fold), hung over their edge then and clear of every kept element; and those
  // hung then that still met one after the separation, put back folded.
  int late_unbent_rings = 0;
  int late_unbending_reverted = 0;
  int separation_reverted = 0;    // moved, then put back: a link would have changed
  int separation_left_shell = 0;  // moved, then put back: it left the shell
  int separation_iterations = 0;
  // Elements mapped through the shell map as it was before stretch optimisation, because the
  // optimised map made them intersect another element.
  int unoptimized_elements = 0;
  // Non-empty when the shell map could not be built and normal displacement was used instead.
  std::string shell_map_failure;
  // Where the shell map was built without some regions of the base (ShellMap's per-region
  // fallback): the base faces left out, their share of the base's area, how many of them were
  // left out where the base folds (the rest where the shell clashes: thin parts, parts a hair
  // apart, a base through itself), why, and the elements placed over them by normal
  // displacement. After a whole-base fallback (shell_map_failure) the share is 1.
  int fallback_faces = 0;
  double fallback_area_share = 0;
  int fallback_fold_faces = 0;
  std::string fallback_reason;
  int fallback_elements = 0;
  // The check of the result (issue 23): per output vertex its signed height over the base as
  // given (core/shell/placement_check). As first embedded: the share of vertices more than
  // `placement_tolerance` shell heights under the base; elements with such a vertex are placed
  // again by normal displacement (replaced_below), and those still under it, then or after the
  // repairs that follow, are removed (removed_below). In the output: the shares under the base
  // (0 by construction) and above the shell, and the lowest signed height in shell heights.
  double placement_tolerance = 0.01;
  double below_base_embedded = 0;
  int replaced_below = 0;
  int lifted_below = 0;  // pushed under the base by the repairs after embedding, lifted out whole
  int removed_below = 0;
  long long checked_vertices = 0;
  double below_base = 0, above_shell = 0, lowest_height = 0;
  int faces = 0, vertices = 0, elements = 0;
  // The output's elements (its connected components, in order) as indices into quilt.elements:
  // those not removed, each with its vertices and faces in the element's order.
  std::vector<int> kept;
  // Spread of element surface areas (how even the texture is over the surface).
  double element_area_mean = 0, element_area_cv = 0, element_area_min = 0, element_area_max = 0;
  // Fraction of the base's area with output geometry within 1.5 shell heights on its outer
  // side (surface_coverage), sampled at the centroids of the refined base's faces; in [0, 1].
  // Over the faces of options.coverage_faces when it is set.
  double coverage = 0;
  StageTimes times;
};

// Embeds the quilt. `stretch` evaluates per-tetrahedron stretch for the shell map (CPU or
// OpenCL); it is unused for normal displacement. Where no valid shell exists over a region of
// the base, the map is built on the rest and elements over that region are placed by normal
// displacement (stats->fallback_*); when no valid shell exists at all, everything is, and
// stats->shell_map_failure says why. Then the result is checked: elements under the base are
// placed again by normal displacement, or removed (stats->replaced_below, removed_below), so
// no output vertex lies more than 1% of the shell height under the base. With stretch
// optimisation, elements that the optimised map makes intersect another element are mapped
// through the map as it was before optimisation (stats->unoptimized_elements). Throws
// DeviceError from the evaluator. Each stage (shell map, stretch optimization, fold repair,
// element removal, coverage) is reported to `progress` as it starts and ends.
TriMesh embed_quilt(const SurfaceQuilt& quilt, const QuiltEmbeddingOptions& options,
                    TetStretchEvaluator& stretch, QuiltEmbeddingStats* stats = nullptr,
                    ProgressSink* progress = nullptr);

}  // namespace mq
