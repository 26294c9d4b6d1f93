// How much of a base surface a quilt covers (issue 4's acceptance measure): a base point counts
// as covered when output geometry lies within a radius of it (1.5 shell heights by convention).
#pragma once

#include "core/mesh.h"

namespace mq {

// Area-weighted fraction of the base (#V by 3 V, #F by 3 F) whose face centroids have a point of
// `output` within `radius`; in [0, 1]. Embree queries, parallel over base faces, deterministic.
// An empty output covers nothing. Throws InvalidInput for a base without faces, non-finite
// vertices, or radius < 0 / NaN.
double surface_coverage(const TriMesh& base, const TriMesh& output, double radius);

}  // namespace mq
