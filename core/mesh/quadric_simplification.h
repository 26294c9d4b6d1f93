// Mesh simplification by quadric error (Garland and Heckbert, "Surface simplification using
// quadric error metrics", SIGGRAPH 1997), with half-edge collapses: every vertex kept is a vertex
// of the input, so the simplified surface touches the input at all its vertices and departs from
// it between them by at most the quadric bound.
//
// Why (issue 14): a base tessellated far finer than the texture (a 1M-face scan under rings a
// hundred faces wide) costs the local patches and the shell map in proportion to its faces
// without changing the result; simplified to the texture's scale within a small fraction of the
// shell height, the job costs what the surface, not its tessellation, asks.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

struct QuadricSimplificationOptions {
  // Largest quadric error of a collapse, as a distance: the square root of the sum of squared
  // distances of the kept vertex from the planes of every input face merged into its faces (so
  // an upper bound on its distance from each). Mesh units; must be >= 0.
  double max_error = 0;
  // No collapse makes an edge longer than this (mesh units, > 0; infinity: no bound).
  double max_edge_length = kInf;
  // A collapse that turns a face's normal by more than this is refused (degrees, in (0, 180)).
  double max_normal_turn_degrees = 45;
  // No collapse makes a face of lower quality (4 sqrt(3) area over the sum of its squared edges:
  // 1 equilateral, 0 degenerate) than this, unless the face was already worse (then none worse
  // than it was). In [0, 1].
  double min_quality = 0.3;
  // Collapsing stops once the mesh has at most this many faces (0: no target; the error bound
  // still stops it first where it is tighter). >= 0.
  int target_faces = 0;
  // Vertices never removed, besides those on boundaries and non-manifold edges (each in
  // [0, #V)): for example the extremes that keep a bounding box.
  std::vector<int> kept_vertices;

  // Throws InvalidInput for a value outside its range (above).
  void validate() const;
};

struct QuadricSimplification {
  TriMesh mesh;                  // vertices a subset of the input's, in input order
  std::vector<int> origin_face;  // #F(mesh): the input face each face was before its corners moved
  std::vector<int> origin_vertex;  // #V(mesh): the input vertex each vertex is
  int collapses = 0;
  double max_error = 0;  // the largest quadric error (as a distance) of a collapse made
};

// Simplifies `mesh` by collapsing edges in order of quadric error while the error stays within
// max_error (and the faces stay above target_faces). Vertices on boundary or non-manifold edges
// and kept_vertices are never removed; a collapse is made
// only where the surface stays a manifold (the link condition), no face flips or turns by more
// than max_normal_turn_degrees, no face falls below min_quality, and no face repeats another.
// Collapses are made cheapest first, up to a factor sqrt(2) in error (bucketed), in the order
// they are found within that: deterministic, O(F) work for the queue.
//   mesh  #V by 3, #F by 3, consistently oriented
// Throws InvalidInput for out-of-range indices (faces or kept_vertices), non-finite coordinates or
// options outside their ranges (options.validate()).
QuadricSimplification simplify_by_quadrics(const TriMesh& mesh,
                                           const QuadricSimplificationOptions& options);

}  // namespace mq
