// How much of a base surface a quilt covers (issue 4's acceptance measure): a base point counts
// as covered when output geometry lies within a radius of it (1.5 shell heights by convention)
// on the base's outer side. Geometry under the base does not cover it (issue 23: rings sunk
// into the open quadruped's legs counted as covering them from within).
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Area-weighted fraction of the base (#V by 3 V, #F by 3 F, faces counter-clockwise seen from
// outside) whose face centroids c have a point q of `output` with |q - c| <= radius and
// (q - c) . n >= -below, n the face's unit normal; in [0, 1]. The nearest such point of each
// output triangle is exact (the triangle clipped by that half-space); an output vertex (of a
// face) within the radius decides first, from a grid of the vertices, and Embree prunes the
// triangles only for the centroids no vertex covers; parallel over base faces, deterministic.
// An empty output covers nothing; a degenerate base face (no normal) counts as covered by any
// point within the radius.
// `faces` (#F(base), or empty: all) limits the measure to the faces set (a mask, issue 25): the
// fraction of their area covered; 0 when none is set.
// Throws InvalidInput for a base without faces, non-finite vertices, radius or below < 0 / NaN,
// `faces` of the wrong size; Error naming the Embree error if Embree fails.
double surface_coverage(const TriMesh& base, const TriMesh& output, double radius,
                        double below = 0.0, const std::vector<char>& faces = {});

// What a swatch covers of its own footprint, measured as above: the footprint (the swatch's
// two longer bounding-box sides, prepare_swatch's frame) sampled by a 48 x 48 grid of squares
// cut in two, radius 1.5 times its thickness, nothing counted more than 1% of the thickness
// under its lowest point. About 1 for chain mail and weave; less for a sparse swatch (vines
// and leaves), whose quilt cannot cover more. Throws as prepare_swatch.
double swatch_coverage(const TriMesh& swatch);

}  // namespace mq
