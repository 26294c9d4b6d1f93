// Exact closest point on a triangle (Ericson, Real-Time Collision Detection, 5.1.5).
// The OpenCL kernels implement the same region tests; tests check that both agree.
#pragma once

#include <Eigen/Core>

namespace mq {

// Closest point on triangle (a, b, c) to p, as barycentric weights (u, v, w) with
// u*a + v*b + w*c the closest point; u + v + w = 1, all >= 0. Degenerate triangles are handled
// (the result is then a closest point on an edge or vertex).
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 1> closest_point_barycentric(const Eigen::Matrix<Scalar, 3, 1>& p,
                                                      const Eigen::Matrix<Scalar, 3, 1>& a,
                                                      const Eigen::Matrix<Scalar, 3, 1>& b,
                                                      const Eigen::Matrix<Scalar, 3, 1>& c) {
  using Vec = Eigen::Matrix<Scalar, 3, 1>;
  const Scalar zero(0), one(1);
  const Vec ab = b - a, ac = c - a, ap = p - a;
  const Scalar d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= zero && d2 <= zero) return Vec(one, zero, zero);
  const Vec bp = p - b;
  const Scalar d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= zero && d4 <= d3) return Vec(zero, one, zero);
  const Scalar vc = d1 * d4 - d3 * d2;
  if (vc <= zero && d1 >= zero && d3 <= zero) {
    const Scalar v = d1 / (d1 - d3);
    return Vec(one - v, v, zero);
  }
  const Vec cp = p - c;
  const Scalar d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= zero && d5 <= d6) return Vec(zero, zero, one);
  const Scalar vb = d5 * d2 - d1 * d6;
  if (vb <= zero && d2 >= zero && d6 <= zero) {
    const Scalar w = d2 / (d2 - d6);
    return Vec(one - w, zero, w);
  }
  const Scalar va = d3 * d6 - d5 * d4;
  if (va <= zero && (d4 - d3) >= zero && (d5 - d6) >= zero) {
    const Scalar w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec(zero, one - w, w);
  }
  const Scalar sum = va + vb + vc;
  if (!(sum > zero)) {
    // Degenerate (collinear) triangle not caught by the region tests: fall back to the best
    // vertex; callers only reach this for zero-area faces.
    const Scalar da = ap.squaredNorm(), db = bp.squaredNorm(), dc = cp.squaredNorm();
    if (da <= db && da <= dc) return Vec(one, zero, zero);
    return db <= dc ? Vec(zero, one, zero) : Vec(zero, zero, one);
  }
  const Scalar denom = one / sum;
  const Scalar v = vb * denom, w = vc * denom;
  return Vec(one - v - w, v, w);
}

// Squared distance from p to triangle (a, b, c).
template <typename Scalar>
Scalar point_triangle_squared_distance(const Eigen::Matrix<Scalar, 3, 1>& p,
                                       const Eigen::Matrix<Scalar, 3, 1>& a,
                                       const Eigen::Matrix<Scalar, 3, 1>& b,
                                       const Eigen::Matrix<Scalar, 3, 1>& c) {
  const Eigen::Matrix<Scalar, 3, 1> w = closest_point_barycentric(p, a, b, c);
  return (p - (w(0) * a + w(1) * b + w(2) * c)).squaredNorm();
}

}  // namespace mq
