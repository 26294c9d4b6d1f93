// How many faces a swatch's pattern holds per unit of footprint area: what a layer of it costs
// before it is made (the --max-faces and memory checks of `plane`).
#pragma once

#include "core/planar/quilt_elements.h"

namespace mq {

// Faces per unit area of the pattern the swatch repeats, in its synthesis frame (xy).
//   swatch  a prepared swatch (prepare_swatch); its footprint has positive area
// Compact elements (no footprint side over 3/4 of the swatch's) are counted inside the convex
// hull of their footprint centres, a centre on the hull weighted by the share of the full turn
// its interior angle takes (a half on an edge): over any triangulation of the hull that is
// Euler's count of points per area, so a lattice's density comes out exactly, however much of
// the swatch's box its border leaves bare or its elements overhang (a ring sheet's box holds
// 0.57-0.76 of the faces per area its pattern has). Elements as long as the swatch (threads)
// and any compact elements whose centres span no area count over the swatch's box.
// Measured against the faces `plane` writes on 30 x 30 to 73 x 73: chain mail 3 x 3, 2 x 4, 6 x 6
// and square 4-in-1 sheets 0.95-1.06, 58 apples 1.02, 11 apples 1.18 (a hull of 11 scattered
// centres), the weave 1.01 (the swatch's box: 0.57-0.89 for the sheets, 0.80 for apples).
double swatch_face_density(const PreparedSwatch& swatch);

}  // namespace mq
