// Stitching two cut elements into one connected component (the mesh merging of section 2.7).
#pragma once

#include <limits>
#include <optional>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/planar/linear_constraint.h"

namespace mq {

struct StitchOptions {
  // Loops whose centroids are farther apart than this are not bridged.
  double max_loop_distance = std::numeric_limits<double>::infinity();
  // Paired loops of equal length lying on each other within this distance, vertex for vertex,
  // are welded instead of bridged (0: never weld).
  double weld_tolerance = 0;
};

struct StitchResult {
  // A's vertices, then B's (indices shifted by A.num_vertices()) but those welded onto A's, then
  // no new vertex; A's faces, then B's, then the bridge triangles. One connected component; the
  // bridged loops leave no boundary edge. N is kept only when both A and B have normals.
  TriMesh mesh;
  // #V(mesh): the vertex of A, or of B shifted by A.num_vertices(), each of mesh's is.
  std::vector<int> origin;
  // One point constraint per seam vertex (mesh numbering): the average of the vertex and its
  // closest point on the opposite loop, ready for the Eq. (5) deformation of the merged part.
  std::vector<LinearConstraint> constraints;
  int bridged_loops = 0;
};

// Joins the cut parts A and B of two corresponding elements (section 2.7).
// Each boundary loop of A is paired with the boundary loop of B whose centroid is nearest
// when the choice is mutual (ties go to the smaller loop index, so the result is
// deterministic). A pair is bridged when the two loops wind in opposite senses (the two sides
// of a seam face each other; a flipped part is refused) and their centroids are at most
// options.max_loop_distance apart. Unpaired loops (e.g. the far ends of an open tube) stay
// open; callers that know the seam scale should set max_loop_distance (e.g. a few mean edge
// lengths), which also keeps far ends of short elements from pairing. Each pair is bridged by a
// zipper strip of triangles: it starts at the closest vertex pair of the two loops, walks A's loop
// backwards and B's loop forwards (so the bridge uses every seam edge in the direction opposite to
// its face, consistently oriented with A and B), and at each step advances along the loop whose new
// diagonal is shorter.
//   A, B  cut parts; each must have a manifold, consistently oriented boundary
// Returns std::nullopt when no loop pair can be bridged or when the bridged result is not one
// connected component, so that the caller falls back to keeping one element whole.
// Limitation: whole loops are bridged; an element whose cut meets a pre-existing boundary
// (seam and original border in one loop) is bridged along that whole loop.
// Throws InvalidInput for an out-of-range index or a non-finite coordinate; TopologyError for
// a non-manifold boundary (see boundary_loops).
std::optional<StitchResult> stitch_cut_elements(const TriMesh& A, const TriMesh& B,
                                                const StitchOptions& options = {});

}  // namespace mq
