// Graph cut of a geometry element on its triangle dual graph (paper section 2.7, Eq. (7)).
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Per-face terminal constraint of the cut.
//   Keep   infinite link to SOURCE: the face is always kept (e.g. outside the overlap region)
//   Remove infinite link to SINK: the face is always removed
//   Free   decided by the minimum cut
enum class CutLabel : unsigned char { Free = 0, Keep = 1, Remove = 2 };

// Result of the element cut.
struct ElementCut {
  std::vector<bool> keep;  // #F, true = the face is kept (SOURCE side)
  double flow = 0;         // the max-flow value, equal to cut_cost(..., keep)
};

// Minimum cut of one element's dual graph (one node per triangle), section 2.7.
// Two triangles sharing the edge (v_i, v_j) are linked with the Eq. (7) weight
//   (1 + |v_i - v_j|) * (1 + d_i + d_j),
// so the cut prefers short edges close to the other element. Solved with Boost.Graph's
// Boykov-Kolmogorov max-flow. The kept set is the SOURCE side of the minimum cut that is
// smallest by inclusion (faces reachable from SOURCE in the residual graph), which is the same
// for every maximum flow: the result is deterministic.
// A dual-graph component (faces linked through shared edges) with no hard label is kept whole;
// one with only Remove labels is removed whole; one with only Keep labels is kept whole.
// Faces sharing a non-manifold edge are all linked pairwise.
//   V              #V by 3 vertex positions (one element)
//   F              #F by 3 vertex indices
//   dist_to_other  #V: Dist(v_i, C_other), distance from each vertex to the other element (>= 0);
//                  only read at the vertices of faces not labelled Keep (edges between two Keep
//                  faces are never cut)
//   hard           #F per-face labels
// A Keep face adjacent to a Remove face is allowed: their shared dual edge is then cut.
// Returns all-false / all-true masks when no face is Keep / Remove (in labelled components).
// Throws InvalidInput on a size mismatch, an out-of-range index, a non-finite coordinate, or a
// negative or non-finite distance.
ElementCut element_graph_cut(const MatrixX3d& V, const MatrixX3i& F,
                             const Eigen::VectorXd& dist_to_other,
                             const std::vector<CutLabel>& hard);

// element_graph_cut(...).keep: the keep mask, #F (true = kept).
std::vector<bool> graph_cut_keep_faces(const MatrixX3d& V, const MatrixX3i& F,
                                       const Eigen::VectorXd& dist_to_other,
                                       const std::vector<CutLabel>& hard);

// Total Eq. (7) weight of the dual edges whose two faces have different keep values.
//   keep  #F
// Throws InvalidInput like element_graph_cut.
double cut_cost(const MatrixX3d& V, const MatrixX3i& F, const Eigen::VectorXd& dist_to_other,
                const std::vector<bool>& keep);

}  // namespace mq
