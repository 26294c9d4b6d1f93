// Geometry matching, paper section 2.4: the placement of the swatch that best continues the
// output around a seed, minimising E(t) of Eqs. (1)-(3) over whole-cell offsets, then refined
// below the cell size on the same cost (majorize-minimize: compass searches with each point's
// best face frozen, then exact reassignment; see refine_offset in the .cpp).
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "core/planar/quilt_elements.h"
#include "core/planar/translation_cost.h"

namespace mq {

struct MatchingOptions {
  // Eq. (1) weight of the distance. It multiplies distances measured in grid cells rather than
  // in the swatch's own units, so a swatch matches the same way whatever its scale.
  double lambda = 1.0;
  // Choose at random among offsets within (1 + epsilon) of the minimum (variety); 0 = the
  // minimum, ties to the lowest candidate index.
  double epsilon = 0.0;
  // Refine the chosen whole-cell offset down to this fraction of a cell (0 disables); the
  // result's exact cost is never above the whole-cell one's. The paper notes finer offsets help;
  // periodic swatches then align exactly.
  double refine_to = 1e-3;
  // Refinement rounds stop once one lowers the exact cost by less than this fraction. On
  // non-periodic swatches (apples) the majorize-minimize rounds creep on with gains of 1e-4 and
  // less: 3e-4 cut plane + apple's rounds from 2,253 to 1,459 (all-points cost per point 1.434
  // vs 1.435); periodic swatches stop earlier anyway (bunny + weave: identical output).
  double refine_tolerance = 3e-4;
  // Sub-patch points used by the refinement and, when refining, by the final choice among the
  // screened candidates (an evenly strided subset when there are more). Scoring the finalists
  // on all (up to 1,024) points instead chose starts whose refined all-points cost was no
  // better (plane + apple: 1.443 vs 1.434 per point) at 3x the queries.
  Eigen::Index refine_points = 128;
  // Screening: when there are more than screen_keep candidates and more than screen_points
  // sub-patch points, every candidate is first scored on an evenly strided subset of
  // screen_points points (the CPU path stops summing a candidate once it cannot be among the
  // best: TranslationCostCpu::least_cost_offsets) and only the screen_keep best are scored on
  // more (the refinement's points, or all of them without refinement) (0 disables).
  // A few dozen points rank whole-cell offsets almost as the full set does, at a fraction of
  // the cost; the final choice is still made with the exact cost over all points. Measured
  // against scoring every candidate on every point: with 32 screening points and 3 finalists
  // the choice was the exhaustive one in 1,111 of 1,117 screened patches on the ivy wall (scale
  // 0.03), 198 of 207 on bunny + weave, 115 of 122 on the armor job and 285 of 289 on plane +
  // apple, and its cost exceeded the exhaustive minimum by 0.05% or less on average (128
  // screening points: 100%, 99%, 99%; most ivy sub-patches have under 128 points, so they
  // were not screened at all). Ivy wall 28 -> 22 s.
  Eigen::Index screen_points = 32;
  int screen_keep = 3;
};

struct OffsetChoice {
  Vector3d offset = Vector3d::Zero();
  double cost = 0;              // E(t) at the chosen offset
  int candidates = 0;           // whole-cell offsets evaluated
  int evaluations = 0;          // exact evaluations of E over a point set, refinement included
  long long point_offsets = 0;  // (point, offset) pairs evaluated
};

// The sub-patch points of Eq. (3): face centroids (#P by 3, with their unit face normals NP) of
// the given elements lying in [lo, hi] (xy), at most max_points of them (an evenly strided
// subset, in element then face order; 0 = all). Degenerate faces are left out.
void gather_subpatch(const std::vector<const Element*>& elements, const Vector2d& lo,
                     const Vector2d& hi, int max_points, MatrixX3d& P, MatrixX3d& NP);

// The whole-cell translations (multiples of cell, t_z = 0) in [t_min, t_max], y-major; when the
// range holds none, t_max alone. #T by 3.
MatrixX3d whole_cell_offsets(const Vector2d& t_min, const Vector2d& t_max, double cell);

// Picks the swatch translation t for the sub-patch points P (#P by 3, unit normals NP #P by 3)
// among `candidates` (#T by 3, whole-cell offsets, at least one). The refinement keeps the xy
// of t inside [t_min, t_max], the continuous range of offsets for which the swatch still covers
// the sub-patch. rng is used only when epsilon > 0. Throws InvalidInput for no candidates.
OffsetChoice choose_offset(const SwatchFaceTree& swatch, TranslationCostEvaluator& evaluator,
                           const MatrixX3d& P, const MatrixX3d& NP, const MatrixX3d& candidates,
                           const Vector2d& t_min, const Vector2d& t_max, double cell_size,
                           const MatchingOptions& options, std::mt19937_64& rng);

}  // namespace mq
