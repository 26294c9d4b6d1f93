// Conforming refinement by longest-edge bisection (Rivara): the longest edge of the whole mesh is
// split at its midpoint, in every face that uses it, until no edge is longer than a bound. Each
// split halves the longest edge of every face it touches, so triangle shapes stay within a
// bounded set of the input's, and small input faces are left alone where uniform 1-to-4
// subdivision refined every face as often as the largest needed (the brick wall's panels and
// its pillars). The surface is unchanged: new vertices lie on old edges.
#pragma once

#include <array>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Where each refined face lies in the input mesh.
struct Refinement {
  std::vector<int> parent;  // #F (refined): the input face containing the face
  // #F (refined) by 9: the barycentric coordinates, in its parent face, of the face's corners
  // 0, 1, 2 (three each).
  Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> corners;
  // Per vertex added, in order (vertex #V(input) + i): the two vertices it is the midpoint of.
  // Replaying them (refine_positions) gives the refined positions of the input moved, bit for
  // bit the same as the bisection's on the input unmoved.
  std::vector<std::array<int, 2>> midpoints;
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
// The refined mesh's positions for the input's vertices at `V` (#V(input) by 3): each added
// vertex the midpoint of its two, in the order they were added.
// Throws InvalidInput when `V` has not the input's vertex count.
MatrixX3d refine_positions(const Refinement& refinement, const MatrixX3d& V, int refined_vertices);

void to_parent(const Refinement& refinement, int& face, Vector3d& b);

}  // namespace mq
