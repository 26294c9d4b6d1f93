// Repair of an element the shell map folds through itself (issue 13): over a sharp crease, or
// next to a cone of the parameterisation, the map bends an element too sharply.
#pragma once

#include "core/mesh/mesh.h"
#include "core/shell/placement_check.h"

namespace mq {

// The element as placed (`placed`, #V by 3) blended towards its flat shape (`flat`, #V by 3: the
// swatch element as the layout placed it) moved by the similarity that best fits where the map
// put it (similarity_fit): as little rigidity as removes the fold. The fitted flat shape is
// whole and unfolded by construction, in the element's place and at its size; the blends keeping
// 95%, 90%, 75%, 50%, 25% of the placed shape are tried first, and the first without a
// self-intersection that stays out of the base (`ground`, if given; a flat ring fitted over a
// convex crease cuts into it: on the armor job 226 of 276, 160 with the blends) is returned.
// Failing that, the first without a self-intersection (the caller lifts it out of the base).
//   F  the element's faces; check  the placement check's options (used with `ground`)
// Throws like self_intersecting_components.
MatrixX3d unfold_element(const MatrixX3d& placed, const MatrixX3d& flat, const MatrixX3i& F,
                         const SignedHeight* ground, const PlacementCheckOptions& check);

}  // namespace mq
