// The symmetries of a swatch that let its texture close up seamlessly around a surface: the
// translations that map it onto itself (the lattice of a periodic sheet such as chain mail or a
// plain weave) and a half turn followed by a translation. A global parameterisation whose
// transitions are such symmetries (core/surface/global_parameterization) carries a planar quilt
// onto a curved base without seams.
#pragma once

#include "core/planar/quilt_elements.h"
#include "core/planar/translation_cost.h"

namespace mq {

struct SwatchSymmetry {
  bool periodic = false;                                // a and b found
  Vector2d a = Vector2d::Zero(), b = Vector2d::Zero();  // shortest independent periods
  bool half_turn = false;
  Vector2d c = Vector2d::Zero();  // -x + c maps the texture onto itself (with half_turn)
};

// Finds the periods by matching the swatch against itself shifted (Eq. (1) of the paper on its
// own face centroids, where the shifted sample overlaps the swatch away from its border):
// whole-cell shifts first, the promising ones refined by a compass search; a shift whose cost
// per point stays within tolerance of an exact match (1) is a period. The half turn likewise,
// matching the swatch turned by pi about the origin.
//   swatch  prepared (synthesis frame), faces = tree built over swatch.mesh
//   cell    the matching grid cell (shifts are searched at half of it)
// Deterministic. Costs about (4 size / cell)^2 x 128 face-tree queries.
SwatchSymmetry detect_swatch_symmetry(const PreparedSwatch& swatch, const SwatchFaceTree& faces,
                                      double cell, double tolerance = 0.02);

// The shortest periods along the x and the y axis alone (0 where there is none), by the same
// self-matching restricted to axis shifts: cheap (a few thousand face-tree queries), for sizing
// the planar sub-patch so that the swatch can still shift by a period.
Vector2d axis_periods(const PreparedSwatch& swatch, const SwatchFaceTree& faces, double cell,
                      double tolerance = 0.02);

// A quick necessary condition for tileable(), a few microseconds per element: at least 4
// elements, none wider than 60% of the swatch along x or y (a thread runs its whole length), and
// some shift between two element centres that takes at least 90% of the centres it keeps inside the
// footprint (and at least 2) onto other centres, within a quarter of the median nearest-centre
// distance. A scattered layer (apples) or a sheet of threads fails it without the self-matching.
bool repeating_elements(const PreparedSwatch& swatch);

// Whether the swatch is a lattice of compact elements: periodic, and one element per lattice
// orbit repeated over the swatch's footprint intersects nothing (rings, apples on a grid).
// Threads that run the whole swatch are not: their copies a period apart overlap.
bool tileable(const PreparedSwatch& swatch, const SwatchSymmetry& symmetry);

// The elements of the swatch one per lattice orbit (elements whose centres differ by a period
// are one orbit): the copy nearest the swatch's centre, ties by index; ascending indices.
std::vector<int> orbit_representatives(const PreparedSwatch& swatch,
                                       const SwatchSymmetry& symmetry);

// The footprint centre of an element (mean of its vertices' x, y).
Vector2d element_centre(const Element& e);

// The planar quilt of a tileable swatch over [lo, hi] (synthesis frame, swatch coordinates):
// one representative per lattice orbit of elements (the copy nearest the swatch's centre),
// repeated at every lattice translation whose copy meets the region. On a periodic swatch every
// patch of section 2's algorithm matches exactly at a period and keeps the output's elements,
// so this is its result, computed directly and without drift.
//   orbits (optional): receives the number of representatives
TriMesh tile_lattice(const PreparedSwatch& swatch, const SwatchSymmetry& symmetry,
                     const Vector2d& lo, const Vector2d& hi, int* orbits = nullptr);

}  // namespace mq
