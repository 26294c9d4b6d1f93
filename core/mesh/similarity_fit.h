// The similarity transform (uniform scale, rotation, translation) that best fits one point set
// onto another in the least-squares sense (Umeyama 1991).
#pragma once

#include "core/mesh/mesh.h"

namespace mq {

// Returns `from` moved by the similarity that takes it nearest to `to`: the rows of both (#V by 3)
// correspond. Reflections are excluded (the rotation's determinant is +1); with all of `from` at
// one point the scale is 1. Preconditions: equal row counts, finite values. Throws nothing.
MatrixX3d similarity_fit(const MatrixX3d& from, const MatrixX3d& to);

}  // namespace mq
