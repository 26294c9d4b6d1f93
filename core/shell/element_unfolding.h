// Repair of an element the shell map folds through itself (issue 13): over a sharp crease, or
// next to a cone of the parameterisation, the map bends an element too sharply.
#pragma once

#include <functional>
#include <utility>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/shell/placement_check.h"

namespace mq {

// The element as placed (`placed`, #V by 3) blended towards its flat shape (`flat`, #V by 3: the
// swatch element as the layout placed it) moved by the similarity that best fits where the map
// put it (similarity_fit): for each share of the placed shape in `keep`, in turn, the blend
// keep * placed + (1 - keep) * fitted is offered to `accept` (which may change it, and keeps
// what it takes) until it returns true. Returns whether one was taken. The step the fold repair
// (unfold_element) and the ring unbending (core/shell/ring_unbending) share.
bool blend_towards_flat(const MatrixX3d& placed, const MatrixX3d& flat,
                        const std::vector<double>& keep,
                        const std::function<bool(MatrixX3d& blend, double keep)>& accept);

// The least rigidity that removes the fold: blend_towards_flat keeping 95%, 90%, 75%, 50%, 25% of
// the placed shape, then none (the fitted flat shape, whole and unfolded by construction, in the
// element's place and at its size); the first without a self-intersection that stays out of the
// base (`ground`, if given; a flat ring fitted over a convex crease cuts into it: on the armor
// job 226 of 276, 160 with the blends) is returned. Failing that, the first without a
// self-intersection (the caller lifts it out of the base).
//   F  the element's faces; check  the placement check's options (used with `ground`)
//   fold  a pair of F's faces, f < g, that intersect in `placed`, if known ({-1, -1} if not):
//         tried first on each blend (mesh_intersections' self_intersects)
// Throws like self_intersecting_components.
MatrixX3d unfold_element(const MatrixX3d& placed, const MatrixX3d& flat, const MatrixX3i& F,
                         const SignedHeight* ground, const PlacementCheckOptions& check,
                         std::pair<int, int> fold = {-1, -1});

}  // namespace mq
