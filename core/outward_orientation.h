// Orientation of a base's components towards their outside, so that the shell (section 3.1:
// the texture grows along the surface normal) lies outside the object. Exporters of CAD and
// architectural models often write boxes with their faces turned inward (the ivy wall of
// ../shared/data: signed volume -18.4), and the texture then grew inside the bricks, hidden.
#pragma once

#include "core/mesh.h"

namespace mq {

// Flips every connected component of `mesh` whose faces mostly face inward, and returns how
// many were flipped. Inward is decided by parity (Jordan): a ray leaving a face along its
// normal crosses the component's own surface an odd number of times when it starts into the
// inside. Up to 16 of a component's largest faces vote; a component flips only on a strict
// majority, so an open sheet (a plane, no crossing either way) and a consistently outward
// surface are left as they are. O(16 F) in all.
// Preconditions: V finite, F indices in range.
int orient_outward(TriMesh& mesh);

}  // namespace mq
