// Orientation of a base's components towards their outside, so that the shell (section 3.1:
// the texture grows along the surface normal) lies outside the object. Exporters of CAD and
// architectural models often write boxes with their faces turned inward (the ivy wall of
// ../shared/data: signed volume -18.4), and the texture then grew inside the bricks, hidden.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Flips every connected component of `mesh` whose faces mostly face inward, and returns how
// many were flipped. Inward is judged by the generalized winding number of the component's own
// surface (Jacobson et al. 2013: the sum of its triangles' signed solid angles over 4 pi) at
// the centroids of up to 32 of its faces spread evenly over its area, each face itself left
// out: the mean of the winding numbers just outside and just inside that face. It is 1/2 on a
// closed surface facing outward and -1/2 facing inward; an open one (a tube with open ends, a
// cup, the ivy wall's boxes open at the bottom) keeps the sign with a smaller size, since no
// ray has to stay inside it to count (the parity of ray crossings, used before, was fooled by
// rays escaping through a quadruped's open legs). A component flips when the mean is below
// -0.05, so an open sheet (a plane: 0 either way) and an outward surface are left as they are.
// O(32 F) solid angles per component, parallel over the samples; deterministic.
// Preconditions: V finite, F indices in range.
int orient_outward(TriMesh& mesh);

// The mean winding number orient_outward judges a component by, for the faces `faces` of
// (V, F) taken as one surface; 0 for no faces. Preconditions as orient_outward.
double mean_surface_winding(const MatrixX3d& V, const MatrixX3i& F, const std::vector<int>& faces);

}  // namespace mq
