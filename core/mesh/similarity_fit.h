// The similarity transform (uniform scale, rotation, translation) that best fits one point set
// onto another in the least-squares sense (Umeyama 1991).
#pragma once

#include "core/mesh/mesh.h"

namespace mq {

// Returns `from` moved by the similarity that takes it nearest to `to`: the rows of both (#V by 3)
// correspond. Reflections are excluded (the rotation's determinant is +1); with all of `from` at
// one point the scale is 1. Preconditions: equal row counts, finite values. Throws nothing.
MatrixX3d similarity_fit(const MatrixX3d& from, const MatrixX3d& to);

// The rotation R nearest to the cross-covariance C = sum_i b_i a_i^T of centred corresponding
// points a_i (from) and b_i (to): R maximises trace(R^T C), so R a_i best fits b_i (Kabsch; a
// reflection is replaced by the nearest rotation). `singular` (optional) receives the
// singular values of C with the reflection's sign applied, whose sum is the fit's covariance for
// the scale. Throws nothing.
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& cross_covariance,
                                 Vector3d* singular = nullptr);

}  // namespace mq
