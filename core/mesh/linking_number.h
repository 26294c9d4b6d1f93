// Topological linking of closed loops, the figure that tells whether two chain mail rings are
// interlinked (paper section 1: the quilt must keep "the integrity of each link"), and the centre
// loop of a ring-shaped geometry element that carries it.
#pragma once

#include <optional>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// A closed polygon: point k joins point k + 1, the last joins the first.
using Loop = std::vector<Vector3d>;

// The linking number of two disjoint closed polygons (each at least 3 points): the signed
// number of times b passes through a surface spanned by a. Computed as the intersection number
// of b with the cone from a's mean point over a (a singular disk whose boundary is a), which is
// exact for any polygons that do not touch; when b grazes an edge of the cone exactly, the
// Gauss integral below decides instead. O(#a #b).
int linking_number(const Loop& a, const Loop& b);

// The Gauss linking integral of two closed polygons, evaluated exactly segment pair by segment
// pair (the signed solid-angle form of Klenin and Langowski, 2000); an integer up to rounding
// when the polygons are disjoint. O(#a #b), slower than linking_number (four asin per pair).
double gauss_linking_integral(const Loop& a, const Loop& b);

// The centre loop of a ring-shaped element: a closed (every edge in two faces) genus-1 surface
// whose vertices surround their mean point in the element's best-fit plane. The vertices are
// binned by their angle about the plane's normal through the mean point, and each bin's mean
// point is a loop point, so the loop runs inside the tube (the core of a torus).
//   V  #V by 3, F  #F by 3 indices into V (one element)
//   bins  loop points (>= 8); halved (down to 8) while some bin holds no vertex, so that a
//         coarse ring of 16 cross sections gets a loop of 16 points
// Returns nothing when the element is not closed, not of genus 1 (Euler characteristic 0),
// or even 8 bins leave one empty (the element does not surround its mean point).
std::optional<Loop> ring_centre_loop(const MatrixX3d& V, const MatrixX3i& F, int bins = 32);

// The binning behind ring_centre_loop, kept to follow a ring as it moves or bends: the loop
// point each vertex belongs to (-1 for a vertex no face uses), and the number of points.
struct RingBins {
  int count = 0;
  std::vector<int> of_vertex;  // #V
};
// Nothing when ring_centre_loop would return nothing. Same arguments and throws.
std::optional<RingBins> ring_loop_bins(const MatrixX3d& V, const MatrixX3i& F, int bins = 32);
// Whether faces F (#F by 3, indices below num_vertices) make a closed (every edge in two faces)
// genus-1 surface: ring_loop_bins' test of the faces, which depends on them alone (copies of
// one ring share it). Throws InvalidInput for an index out of range.
bool closed_genus_one(const MatrixX3i& F, Eigen::Index num_vertices);
// ring_loop_bins without the test of the faces, for faces known closed_genus_one. Same throws.
std::optional<RingBins> ring_loop_bins_unchecked(const MatrixX3d& V, const MatrixX3i& F,
                                                 int bins = 32);
// The centre loop of positions V binned by `bins` (found on these or on other positions of
// the same vertices: a ring's flat shape bins its bent copies). Throws InvalidInput when the
// sizes differ.
Loop loop_from_bins(const MatrixX3d& V, const RingBins& bins);

// How open and how flat a ring is: the figures that decide whether a link through it can be
// real. A ring squeezed until its hole closes, or folded over a crease into a C, still has a
// centre loop that other loops pass through, but no wire can pass through its hole, or it no
// longer lies like a ring (issue 23).
struct RingShape {
  // Wire diameter: area / (pi * loop length). A tube of radius r around a loop of length L has
  // area 2 pi r L whatever the loop's curvature (while the tube does not overlap itself), so this
  // is exact for a round wire and the area-equivalent width of a squashed one.
  double wire = 0;
  // The free hole: the diameter of the largest disk in the loop's best-fit plane, centred inside
  // the loop projected there, that no vertex of the ring projected there enters (the hole seen
  // along the ring's axis; 0 when the loop encloses nothing).
  double opening = 0;
  // Radians in [0, pi]: the largest angle between the best-fit plane normals of the loop's two
  // halves, over every split of the loop into two halves of consecutive points (normals turned
  // towards the whole loop's area normal). 0 for any planar loop, whatever its outline (a
  // crescent too); about pi/2 for a ring folded over a right-angled edge through its centre.
  double fold = 0;
};

// The shape figures of a ring-shaped element and its centre loop (ring_centre_loop's).
//   V  #V by 3, F  #F by 3 indices into V (one element; vertices no face uses are ignored)
//   loop  at least 4 points
// Throws InvalidInput for a shorter loop or an out-of-range index. O(#V + #F + #loop^2) with a
// few dozen evaluations of the vertices' distance for the hole.
RingShape ring_shape(const MatrixX3d& V, const MatrixX3i& F, const Loop& loop);

// RingShape::fold alone (it depends on the loop only; ring_shape's hole costs most of its time).
// Throws InvalidInput for a loop of fewer than 4 points.
double ring_fold(const Loop& loop);

}  // namespace mq
