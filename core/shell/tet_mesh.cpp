#include "core/shell/tet_mesh.h"

#include "core/common/errors.h"

namespace mq {

Eigen::VectorXd tet_volumes(const MatrixX3d& V, const TetIndices& T) {
  MQ_CHECK(T.rows() == 0 || (T.minCoeff() >= 0 && T.maxCoeff() < V.rows()), InvalidInput,
           "tet volumes: tet index out of range [0, ", V.rows(), ")");
  Eigen::VectorXd vol(T.rows());
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    vol(t) = tet_volume(V.row(T(t, 0)), V.row(T(t, 1)), V.row(T(t, 2)), V.row(T(t, 3)));
  return vol;
}

}  // namespace mq
