// A linear position constraint on one to three vertices, the unit of Eqs. (5) and (6).
#pragma once

#include <array>

#include "core/mesh/mesh.h"

namespace mq {

// sum_k weights[k] * w(vertices[k]) should equal target. Unused slots have vertex -1 and
// weight 0. A point constraint (Eq. (5)) uses one slot; a barycentric constraint on the
// triangle (a, b, c) (Eq. (6)) uses all three.
struct LinearConstraint {
  std::array<int, 3> vertices{{-1, -1, -1}};
  std::array<double, 3> weights{{0, 0, 0}};
  Vector3d target = Vector3d::Zero();

  // w(v) = target.
  static LinearConstraint point(int v, const Vector3d& target) {
    LinearConstraint c;
    c.vertices = {{v, -1, -1}};
    c.weights = {{1.0, 0.0, 0.0}};
    c.target = target;
    return c;
  }

  // w(a) * w.x + w(b) * w.y + w(c) * w.z = target.
  static LinearConstraint barycentric(int a, int b, int c, const Vector3d& w,
                                      const Vector3d& target) {
    LinearConstraint lc;
    lc.vertices = {{a, b, c}};
    lc.weights = {{w.x(), w.y(), w.z()}};
    lc.target = target;
    return lc;
  }
};

}  // namespace mq
