#include "core/planar/swatch_density.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mq {

namespace {

// An element is compact when none of its footprint sides exceeds this share of the swatch's:
// a thread runs the swatch's length, a ring of a two-row sheet spans 0.6 of its width.
constexpr double kCompactShare = 0.75;

double cross(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Indices of the strictly convex hull of p, counter-clockwise (Andrew's monotone chain);
// collinear points are left out of it.
std::vector<int> convex_hull(const std::vector<Vector2d>& p) {
  std::vector<int> order(p.size());
  for (size_t i = 0; i < p.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return p[a].x() < p[b].x() || (p[a].x() == p[b].x() && p[a].y() < p[b].y());
  });
  std::vector<int> hull(2 * p.size());
  size_t k = 0;
  const auto turn = [&](int o, int a, int b) { return cross(p[a] - p[o], p[b] - p[o]); };
  for (int i : order) {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], i) <= 0) --k;
    hull[k++] = i;
  }
  for (size_t j = order.size() - 1, lower = k + 1; j-- > 0;) {
    const int i = order[j];
    while (k >= lower && turn(hull[k - 2], hull[k - 1], i) <= 0) --k;
    hull[k++] = i;
  }
  hull.resize(k > 1 ? k - 1 : k);
  return hull;
}

// The angle-weighted count of compact elements' faces inside the hull of their centres, and
// the hull's area; false when the centres span no area.
bool hull_count(const std::vector<Vector2d>& centre, const std::vector<double>& faces,
                double tolerance, double& weighted_faces, double& area) {
  if (centre.size() < 3) return false;
  const std::vector<int> hull = convex_hull(centre);
  const size_t h = hull.size();
  if (h < 3) return false;
  area = 0;
  for (size_t k = 0; k < h; ++k) area += cross(centre[hull[k]], centre[hull[(k + 1) % h]]) / 2;
  if (!(area > tolerance * tolerance)) return false;
  std::vector<double> weight(centre.size(), 1.0);
  for (size_t i = 0; i < centre.size(); ++i)
    for (size_t k = 0; k < h; ++k) {  // on an edge: half a turn
      const Vector2d& a = centre[hull[k]];
      const Vector2d e = centre[hull[(k + 1) % h]] - a;
      const double t = (centre[i] - a).dot(e) / e.squaredNorm();
      if (t > 0 && t < 1 && std::abs(cross(e, centre[i] - a)) <= tolerance * e.norm())
        weight[i] = 0.5;
    }
  for (size_t k = 0; k < h; ++k) {  // a corner: its interior angle's share of the turn
    const Vector2d& b = centre[hull[k]];
    const Vector2d u = centre[hull[(k + h - 1) % h]] - b, v = centre[hull[(k + 1) % h]] - b;
    weight[static_cast<size_t>(hull[k])] = std::atan2(std::abs(cross(u, v)), u.dot(v)) / (2 * M_PI);
  }
  weighted_faces = 0;
  for (size_t i = 0; i < centre.size(); ++i) weighted_faces += weight[i] * faces[i];
  return true;
}

}  // namespace

SwatchFaceDensity swatch_face_density(const PreparedSwatch& swatch) {
  const double sx = swatch.size.x(), sy = swatch.size.y();
  std::vector<Vector2d> centre;
  std::vector<double> faces;
  SwatchFaceDensity d;
  for (const Element& e : swatch.elements) {
    const Vector2d side = e.hi - e.lo;
    const auto n = static_cast<double>(e.F.rows());
    if (side.x() <= kCompactShare * sx && side.y() <= kCompactShare * sy) {
      centre.push_back((e.lo + e.hi) / 2);
      faces.push_back(n);
    } else {
      (side.x() / sx >= side.y() / sy ? d.along_x : d.along_y) += n / (sx * sy);
    }
  }
  double weighted = 0, area = 0;
  if (hull_count(centre, faces, 1e-6 * std::max(sx, sy), weighted, area)) {
    d.compact = weighted / area;
  } else {
    for (double f : faces) d.compact += f / (sx * sy);
  }
  return d;
}

}  // namespace mq
