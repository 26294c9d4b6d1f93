// Conforming refinement by longest-edge bisection (Rivara): the longest edge of the whole mesh is
// split at its midpoint, in every face that uses it, until no edge is longer than a bound. Each
// split halves the longest edge of every face it touches, so triangle shapes stay within a
// bounded set of the input's, and small input faces are left alone where uniform 1-to-4
// subdivision refined every face as often as the largest needed (the brick wall's panels and
// its pillars). The surface is unchanged: new vertices lie on old edges.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Where each refined face lies in the input mesh.
struct Refinement {
  std::vector<int> parent;  // #F (refined): the input face containing the face
  // #F (refined) by 9: the barycentric coordinates, in its parent face, of the face's corners
  // 0, 1, 2 (three each).
  Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> corners;
};

// Splits edges longer than max_edge, longest first (ties by vertex ids, so the result is
// deterministic), while the face count stays at most max_faces. Faces keep their orientation;
// an edge shared by several faces gets one midpoint, so the result is watertight where the input
// was. Normals are not carried over.
//   refinement  optional output: parent faces and corner coordinates (#F of the result)
// Throws InvalidInput for an index out of range, a non-finite position, or max_edge not
// positive and finite.
TriMesh bisect_longest_edges(const TriMesh& mesh, double max_edge, int max_faces,
                             Refinement* refinement = nullptr);

// Maps the point with barycentric coordinates b in refined face `face` to its input face and
// barycentric coordinates there (in place). Exact: refined faces are affine pieces of their
// parents. Precondition: face < refinement.parent.size().
void to_parent(const Refinement& refinement, int& face, Vector3d& b);

}  // namespace mq
