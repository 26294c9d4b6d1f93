// Local coordinates of points over a base mesh (paper section 3.2: the output lives in them over
// the base until the final embedding places it): the one type for a face, barycentric
// coordinates and a height.
#pragma once

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace mq {

// Local coordinates of #P points over a base mesh.
//   face    #P base face ids
//   bary    #P by 3 barycentric coordinates (b0, b1, b2) in face's corner order, summing to 1
//           (>= 0 inside the face; a little below 0 past its edge, where a point of the shell
//           lies over a neighbour's prism)
//   height  #P heights above the base in the base's units (0 <= h <= H in the shell)
struct LocalCoordinates {
  Eigen::VectorXi face;
  MatrixX3d bary;
  Eigen::VectorXd height;

  int size() const { return static_cast<int>(face.size()); }
};

}  // namespace mq
