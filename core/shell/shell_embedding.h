// Final embedding of paper section 3.2: output vertices given in local coordinates over the
// base surface (face, barycentric coordinates, height) are placed in 3D through the shell map
// (texture space -> shell space), or, for comparison, by plain normal displacement.
#pragma once

#include <Eigen/Core>

#include "core/mesh/local_coordinates.h"
#include "core/mesh/mesh.h"
#include "core/shell/shell_map.h"

namespace mq {

// Precomputed point location in the texture tets of a shell map: per texture tet its inverse
// edge matrix, and per chart a uniform 2D grid over the (u, v) bounding boxes of its tets.
// A snapshot: later optimisation of the ShellMap does not affect it.
class ShellEmbedding {
 public:
  // Throws nothing beyond std::bad_alloc.
  explicit ShellEmbedding(const ShellMap& map);

  // The 3D positions g^-1(p) of the texture points p = (sum_i b_i UV(FUV(f, i)), h): p is
  // located among the 3 texture tets of face f's prism and, when the optimised offset (u, v)
  // have shifted it out of them, among the chart's tets through the chart's grid (the tet with
  // the largest smallest barycentric coordinate wins, so ties on shared faces are deterministic),
  // then mapped by its barycentric coordinates into the shell tet. TBB over points, each writing
  // its own row: independent of the thread count.
  //   tet  optional output: #P tet of each point (row of ShellMap::problem().T)
  // Returns #P by 3. Throws InvalidInput for a face out of range, barycentric coordinates not
  // finite, below -1e-9 or not summing to 1 within 1e-6, or a height outside [0, H] (relative
  // tolerance 1e-9).
  MatrixX3d embed(const LocalCoordinates& points, Eigen::VectorXi* tet = nullptr) const;

  // Number of texture tets (3 per base face).
  int num_texture_tets() const { return static_cast<int>(T_.rows()); }

 private:
  MatrixX3d shell_V_, texture_V_;
  TetIndices T_;
  MatrixX2d UV_;
  MatrixX3i FUV_;
  std::vector<int> face_chart_;
  double height_ = 0.0;
  std::vector<Eigen::Matrix3d> inverse_;  // per tet: inverse of its texture edge matrix
  struct Grid {
    Vector2d lo = Vector2d::Zero();
    double cell = 1.0;
    int nx = 1, ny = 1;
    std::vector<int> offsets, tets;  // CSR over nx * ny cells
  };
  std::vector<Grid> grids_;  // per chart
};

// Plain normal displacement: sum_i b_i V_i + h * normalize(sum_i b_i N_i), N the area-weighted
// vertex normals of (V, F). TBB over points.
//   V #V by 3, F #F by 3 (the base), points as above (heights any finite value)
// Returns #P by 3. Throws InvalidInput for an index out of range or non-finite input;
// TopologyError when an interpolated normal vanishes.
MatrixX3d normal_displacement(const MatrixX3d& V, const MatrixX3i& F,
                              const LocalCoordinates& points);

// The same along given per-vertex directions N (#V by 3, any length; interpolated and
// normalised), such as the shell's smoothed offset directions.
MatrixX3d normal_displacement(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N,
                              const LocalCoordinates& points);

}  // namespace mq
