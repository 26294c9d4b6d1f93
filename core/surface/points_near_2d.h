// "Is any point within a radius of q?" for 2D points in a uniform hash grid of that radius:
// the 3 x 3 cells around q hold every candidate. Used to mark the faces of a patch that output
// geometry covers (paper section 3.1, issue 4's coverage criterion).
#pragma once

#include <cmath>
#include <unordered_map>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

class PointsNear2D {
 public:
  explicit PointsNear2D(double radius) : r_(radius) {}  // radius > 0
  void add(const Vector2d& p) { cells_[key(cell_of(p.x()), cell_of(p.y()))].push_back(p); }
  bool any_within(const Vector2d& q) const {
    const long long cx = cell_of(q.x()), cy = cell_of(q.y());
    for (long long y = cy - 1; y <= cy + 1; ++y)
      for (long long x = cx - 1; x <= cx + 1; ++x) {
        auto it = cells_.find(key(x, y));
        if (it == cells_.end()) continue;
        for (const Vector2d& p : it->second)
          if ((p - q).squaredNorm() <= r_ * r_) return true;
      }
    return false;
  }

 private:
  long long cell_of(double v) const { return static_cast<long long>(std::floor(v / r_)); }
  static long long key(long long x, long long y) { return x * 73856093LL ^ y * 19349663LL; }
  double r_;
  std::unordered_map<long long, std::vector<Vector2d>> cells_;
};

}  // namespace mq
