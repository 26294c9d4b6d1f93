// How many faces a swatch's pattern holds per unit of footprint area: what a layer of it costs
// before it is made (the --max-faces and memory checks of `plane`).
#pragma once

#include "core/planar/quilt_elements.h"

namespace mq {

// Faces per unit area of the pattern the swatch repeats, in its synthesis frame (xy), apart by
// how they extend past the border of a layer: compact elements (no footprint side over 3/4 of
// the swatch's) sit within it, elements as long as the swatch (threads) run on past it.
struct SwatchFaceDensity {
  // Compact elements, counted inside the convex hull of their footprint centres, a centre on
  // the hull weighted by the share of the full turn its interior angle takes (a half on an
  // edge): over any triangulation of the hull that is Euler's count of points per area, so a
  // lattice's density comes out exactly, however much of the swatch's box its border leaves
  // bare or its elements overhang (a ring sheet's box holds 0.57-0.76 of the faces per area its
  // pattern has). Over the swatch's box when their centres span no area.
  double compact = 0;
  // The others over the swatch's box, by their longer footprint side.
  double along_x = 0, along_y = 0;
};

// Precondition: swatch is a prepared swatch (prepare_swatch), its footprint of positive area.
SwatchFaceDensity swatch_face_density(const PreparedSwatch& swatch);

}  // namespace mq
