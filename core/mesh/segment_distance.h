// Closest points between a point and a segment and between two segments (Ericson, Real-Time
// Collision Detection, 5.1.2 and 5.1.9): the ring centre loops of the structure measure and of
// ring separation are polylines.
#pragma once

#include <algorithm>

#include "core/mesh/mesh.h"

namespace mq {

// Distance from p to the closed segment ab (to a when a == b).
inline double point_segment_distance(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
  const Vector3d d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

// Closest points of the closed segments p0 p1 and q0 q1: p0 + s (p1 - p0) and q0 + t (q1 - q0)
// with s, t in [0, 1]. A segment of zero length is its point; for parallel segments one of the
// closest pairs.
inline void closest_points_on_segments(const Vector3d& p0, const Vector3d& p1, const Vector3d& q0,
                                       const Vector3d& q1, double& s, double& t) {
  const Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double tiny = 1e-300;
  if (a <= tiny && e <= tiny) {
    s = t = 0;
    return;
  }
  if (a <= tiny) {
    s = 0;
    t = std::clamp(f / e, 0.0, 1.0);
    return;
  }
  const double c = d1.dot(r);
  if (e <= tiny) {
    t = 0;
    s = std::clamp(-c / a, 0.0, 1.0);
    return;
  }
  const double b = d1.dot(d2), denom = a * e - b * b;
  s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  t = (b * s + f) / e;
  if (t < 0) {
    t = 0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1) {
    t = 1;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
}

}  // namespace mq
