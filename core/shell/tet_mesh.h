// Tetrahedral meshes: the shell space of paper section 3.2 and its texture-space image.
#pragma once

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace mq {

// #T by 4 vertex indices of tetrahedra; positive orientation means
// det(v1 - v0, v2 - v0, v3 - v0) > 0.
using TetIndices = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;

// A tetrahedral mesh.
//   V  #V by 3 vertex positions
//   T  #T by 4 indices into V
struct TetMesh {
  MatrixX3d V;
  TetIndices T;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_tets() const { return static_cast<int>(T.rows()); }
};

// Signed volume det(b - a, c - a, d - a) / 6.
inline double tet_volume(const Vector3d& a, const Vector3d& b, const Vector3d& c,
                         const Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

// Signed volumes of the tets of (V, T). Returns #T.
// Throws InvalidInput for an index outside [0, #V).
Eigen::VectorXd tet_volumes(const MatrixX3d& V, const TetIndices& T);
inline Eigen::VectorXd tet_volumes(const TetMesh& mesh) { return tet_volumes(mesh.V, mesh.T); }

}  // namespace mq
