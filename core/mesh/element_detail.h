// A swatch at a lower level of detail: each element (connected component) simplified on its own
// by quadric error to a share of its faces.
//
// Why (issue 26): every stage after the layout (embedding, fold repair, ring separation, the
// intersection test, coverage, writing) costs in proportion to the output's faces, and a ring of
// the sample chain mail has 1,152 of them. A Preview at a tenth of the faces is the same job 5-7x
// faster; a final render may not need the swatch's full detail either. Half-edge collapses keep
// input vertices, so a simplified element lies within its original (inscribed in a convex tube:
// thinner, never thicker), and elements that did not intersect still do not.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/quadric_simplification.h"

namespace mq {

struct ElementDetailOptions {
  // Share of each element's faces to keep, in (0, 1]; 1 keeps the swatch as it is.
  double detail = 1;
  // No element is simplified below this many faces (or its own count, if smaller). >= 4.
  int min_faces = 24;

  // Throws InvalidInput for a value outside its range (above).
  void validate() const;
};

struct ElementDetail {
  TriMesh mesh;              // the simplified swatch: elements in input order, kinds kept
  int elements = 0;          // connected components
  int groups = 0;            // of congruent copies, each simplified once (0 at full detail)
  int raised = 0;            // groups given more faces so that nothing came to intersect
  int max_faces_before = 0;  // faces of the largest element, before and after
  int max_faces_after = 0;
  int median_faces_before = 0;  // median faces per element, before and after
  int median_faces_after = 0;
};

// Simplifies every element of `swatch` to about detail x its faces (never below min_faces) by
// quadric error (core/mesh/quadric_simplification.h): the surface stays a closed manifold of
// the same topology wherever it was one (the link condition), so a ring keeps its hole; each
// element keeps a vertex at each of its six bounding-box extremes, so the element's and the
// swatch's bounding boxes (the shell height and the scale, section 3.2) are unchanged. An
// element that would come to intersect itself or another element (a coarse wire folding, a chord
// cutting into a neighbour), which it did not at full detail, keeps more faces. Congruent
// copies of an element (same connectivity and edge lengths) are simplified alike, so a periodic
// swatch stays periodic. The elements are simplified in parallel; the result does not depend on
// the thread count.
//   swatch  #V by 3, #F by 3, with optional face kinds (kept per face) and vertex normals (kept
//           per vertex)
// Throws InvalidInput for options outside their ranges, out-of-range indices or non-finite
// coordinates.
ElementDetail reduce_element_detail(const TriMesh& swatch, const ElementDetailOptions& options);

// One piece of surface simplified as reduce_element_detail simplifies an element: to about
// share x its faces (never below min_faces, or its own count), its boundary vertices and `kept`
// staying where they are (a thread piece's cut loops, so that pieces still weld; the layout's
// thread pieces are cut from the swatch at full detail, core/surface/thread_tiling.h).
//   mesh  #V by 3, #F by 3; kept  indices into V
// Throws InvalidInput for share outside (0, 1], min_faces < 4 or what simplify_by_quadrics
// throws for.
QuadricSimplification simplify_to_share(const TriMesh& mesh, double share, int min_faces,
                                        const std::vector<int>& kept = {});

}  // namespace mq
