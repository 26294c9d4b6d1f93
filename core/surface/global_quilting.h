// Mesh quilting over a curved surface through one field-aligned global parameterisation: the
// planar algorithm of section 2 grows the swatch over the parameter plane, and every element is
// carried onto the base through the charts (core/surface/global_parameterization).
//
// Why, beyond the paper's section 3.1: there, each patch is flattened on its own and the
// texture the earlier patches placed is seen through a slightly different map; on a curved base
// the misfit between neighbouring patches (a few percent of scale and turn) is more than chain
// mail's clearance, and rings come out disjoint or missing along every seam (measured: 60% of
// interior rings with their 4 links on a sphere, 36% on Spot). Through one parameterisation the
// planar quilt keeps its structure everywhere the charts agree: inside each chart exactly, and
// across the cut graph up to the rigid transition between charts.
#pragma once

#include "core/surface/surface_quilting.h"

namespace mq {

struct VineGrowthStats;

struct GlobalQuiltingStats {
  bool periodic = false;         // the swatch's lattice was found (core/planar/swatch_symmetry)
  bool seamless = false;         // cones pinned and transitions fixed at the texture's symmetries
  bool tiled = false;            // the plane texture is the lattice tiling (else a planar quilt)
  int orbits = 0;                // elements per lattice cell, when tiled
  int singular_vertices = 0;     // of the line field, after cancelling adjacent pairs
  int cancelled_cone_pairs = 0;  // adjacent + and - singularities of the field
  // Cone placement (core/surface/cone_placement): poles split, moves, + and - cone pairs
  // cancelled within its allowance of scale, and the mean squared log scale of the flat cone
  // metric before and after.
  int split_poles = 0, cone_moves = 0, placement_pairs_cancelled = 0;
  // How far the layout followed the cone metric's scale e^u: e^(a u), a in [0, 1]
  // (SurfaceQuiltingOptions::Global::max_overfill); 0 when the layout is not conformal.
  double scale_exponent = 0;
  double scale_energy_before = 0, scale_energy = 0;
  int pinned_cones = 0;
  // #singular_vertices by 3: where the cones are on the base, in the base's units (a ring
  // lattice's defects: most of its misses lie within a ring or two of one).
  MatrixX3d cones;
  int cut_edges = 0, cut_paths = 0;
  // Largest distance of a transition from the texture's nearest symmetry, in lattice periods
  // (the constraints are soft; a ring's clearance in the 4-in-1 sheet is about 0.2).
  double worst_transition_error = 0;
  double scale_correction = 1;  // the parameterisation's scale, made 1 at the median face
  double parameter_area = 0;    // of the parameter plane textured
  double layout_faces = 0;      // faces of the lattice copies, counted before any is built
  int placed = 0;               // elements carried onto the base
  int off_surface = 0;          // left out: a vertex beyond a boundary or around a singular vertex
  // Placed as copies of the layout's first-order image at their centre (the layout itself
  // would have distorted them; SurfaceQuiltingOptions::Global::placement).
  int copied_elements = 0;
  // A periodic swatch of threads (core/surface/thread_tiling): its one-period pieces tiled and
  // welded.
  bool threads = false;
  int thread_pieces = 0;        // pieces placed (those off the surface count in off_surface)
  int pieces_distorted = 0;     // left out: the layout bends them out of shape
  int pieces_near_cones = 0;    // left out: within a thread spacing of a cone
  int pieces_intersecting = 0;  // left out: intersecting others (normal displacement)
  int thread_welds = 0;         // loops where two pieces were joined
  int thread_ends = 0;          // loops left open, capped
  int closed_threads = 0;       // threads closed on themselves
  int short_threads = 0;        // threads of a single piece, left out
};

// Like quilt_surface (same options, same result), through a global parameterisation: a lattice
// of compact elements is tiled, a lattice of threads tiled by one-period pieces welded into
// threads, any other swatch quilted over the parameter plane. Throws like quilt_surface.
SurfaceQuilt quilt_surface_global(const TriMesh& base, const TriMesh& swatch,
                                  const SurfaceQuiltingOptions& options,
                                  TranslationCostEvaluator& evaluator,
                                  SurfaceQuiltingStats* stats = nullptr,
                                  GlobalQuiltingStats* global_stats = nullptr,
                                  ProgressSink* progress = nullptr);

// --method auto: quilt_surface_global for a lattice of compact elements (periodic and
// tileable, core/planar/swatch_symmetry) or of threads (core/surface/thread_tiling): the textures
// whose structure the patch method loses (links, threads that run on), decided on the swatch at the
// job's scale; quilt_prepared_vines (core/surface/vine_growth) for a vine with compact elements
// attached along it (is_vine_swatch: the ivy section); quilt_surface otherwise. The swatch's
// symmetry is found once. *used_global and *used_vines (optional) say which ran, *vine_stats
// (optional) gets the vines' figures. Throws like quilt_surface.
SurfaceQuilt quilt_surface_auto(const TriMesh& base, const TriMesh& swatch,
                                const SurfaceQuiltingOptions& options,
                                TranslationCostEvaluator& evaluator,
                                SurfaceQuiltingStats* stats = nullptr,
                                GlobalQuiltingStats* global_stats = nullptr,
                                ProgressSink* progress = nullptr, bool* used_global = nullptr,
                                bool* used_vines = nullptr, VineGrowthStats* vine_stats = nullptr);

}  // namespace mq
