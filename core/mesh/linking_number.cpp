#include "core/mesh/linking_number.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

namespace {

// Six times the signed volume of the tetrahedron (a, b, c, d).
double orient(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a));
}

int sign_of(double x) { return (x > 0) - (x < 0); }

Vector3d mean_point(const Loop& a) {
  Vector3d c = Vector3d::Zero();
  for (const Vector3d& p : a) c += p;
  return c / static_cast<double>(a.size());
}

}  // namespace

double gauss_linking_integral(const Loop& a, const Loop& b) {
  MQ_CHECK(a.size() >= 3 && b.size() >= 3, InvalidInput, "a loop needs at least 3 points");
  double total = 0;
  const size_t na = a.size(), nb = b.size();
  for (size_t i = 0; i < na; ++i) {
    const Vector3d& p1 = a[i];
    const Vector3d& p2 = a[(i + 1) % na];
    for (size_t j = 0; j < nb; ++j) {
      const Vector3d& p3 = b[j];
      const Vector3d& p4 = b[(j + 1) % nb];
      const Vector3d r13 = p3 - p1, r14 = p4 - p1, r23 = p3 - p2, r24 = p4 - p2;
      Vector3d n[4] = {r13.cross(r14), r14.cross(r24), r24.cross(r23), r23.cross(r13)};
      bool degenerate = false;
      for (Vector3d& v : n) {
        const double len = v.norm();
        if (!(len > 0)) degenerate = true;
        v /= len;
      }
      if (degenerate) continue;  // coplanar segments: zero solid angle
      double omega = 0;
      for (int k = 0; k < 4; ++k)
        omega += std::asin(std::clamp(n[k].dot(n[(k + 1) % 4]), -1.0, 1.0));
      const double s = (p4 - p3).cross(p2 - p1).dot(r13);
      total += omega * sign_of(s);
    }
  }
  // Signed as linking_number counts: b passing along the normal of a's right-handed disk.
  return total / (4 * M_PI);
}

int linking_number(const Loop& a, const Loop& b) {
  MQ_CHECK(a.size() >= 3 && b.size() >= 3, InvalidInput, "a loop needs at least 3 points");
  const Vector3d c = mean_point(a);
  const size_t na = a.size(), nb = b.size();
  // Cone triangle k is (c, a[k], a[k+1]). Each cone edge (c, a[k]) is shared by triangles k-1
  // and k: its orientation against a segment is computed once and used with opposite signs, so
  // a segment passing near a shared edge counts in exactly one of the two triangles.
  std::vector<double> e(na + 1);
  int crossings = 0;
  for (size_t j = 0; j < nb; ++j) {
    const Vector3d& p = b[j];
    const Vector3d& q = b[(j + 1) % nb];
    for (size_t k = 0; k < na; ++k) e[k] = orient(p, q, c, a[k]);
    e[na] = e[0];
    for (size_t k = 0; k < na; ++k) {
      const Vector3d& a0 = a[k];
      const Vector3d& a1 = a[(k + 1) % na];
      const double hp = orient(c, a0, a1, p), hq = orient(c, a0, a1, q);
      if ((hp > 0 && hq > 0) || (hp < 0 && hq < 0)) continue;  // same side of the plane
      const double g = orient(p, q, a0, a1);
      const int s0 = sign_of(e[k]), s1 = sign_of(g), s2 = sign_of(-e[k + 1]);
      // Two edge signs that disagree: the segment's line misses the triangle.
      if (s0 * s1 < 0 || s1 * s2 < 0 || s0 * s2 < 0) continue;
      if (hp == 0 || hq == 0 || s0 == 0 || s1 == 0 || s2 == 0) {
        // b touches the cone's plane or an edge exactly: a measure-zero case the sign tests
        // cannot settle; the Gauss integral is continuous there.
        return static_cast<int>(std::lround(gauss_linking_integral(a, b)));
      }
      // hp, hq are the heights of p, q along the triangle's normal (a0 - c) x (a1 - c).
      crossings += hq > hp ? 1 : -1;
    }
  }
  return crossings;
}

bool closed_genus_one(const MatrixX3i& F, Eigen::Index num_vertices) {
  if (F.rows() == 0 || num_vertices == 0) return false;
  MQ_CHECK(F.minCoeff() >= 0 && F.maxCoeff() < num_vertices, InvalidInput,
           "closed_genus_one: a face index is out of range");
  const EdgeTopology topo = edge_topology(F, static_cast<int>(num_vertices));
  for (int e = 0; e < topo.num_edges(); ++e)
    if (topo.edge_faces.degree(e) != 2) return false;
  std::vector<char> used(static_cast<size_t>(num_vertices), 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[F(f, k)] = 1;
  const auto nv = std::count(used.begin(), used.end(), 1);
  // Euler characteristic V - E + F of a closed genus-1 surface is 0.
  return nv - topo.num_edges() + F.rows() == 0;
}

std::optional<RingBins> ring_loop_bins(const MatrixX3d& V, const MatrixX3i& F, int bins) {
  MQ_CHECK(bins >= 8, InvalidInput, "a centre loop needs at least 8 bins, got ", bins);
  if (!closed_genus_one(F, V.rows())) return std::nullopt;
  return ring_loop_bins_unchecked(V, F, bins);
}

std::optional<RingBins> ring_loop_bins_unchecked(const MatrixX3d& V, const MatrixX3i& F, int bins) {
  MQ_CHECK(bins >= 8, InvalidInput, "a centre loop needs at least 8 bins, got ", bins);
  if (F.rows() == 0 || V.rows() == 0) return std::nullopt;
  std::vector<char> used(V.rows(), 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[F(f, k)] = 1;
  long long nv = 0;
  Vector3d mean = Vector3d::Zero();
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) {
      ++nv;
      mean += V.row(v).transpose();
    }
  mean /= static_cast<double>(nv);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) {
      const Vector3d d = V.row(v).transpose() - mean;
      cov += d * d.transpose();
    }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  // Eigenvalues ascending: the smallest spread is the ring's normal.
  const Vector3d u = eig.eigenvectors().col(2), w = eig.eigenvectors().col(1);
  std::vector<double> angle(V.rows(), 0);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const Vector3d d = V.row(v).transpose() - mean;
    angle[v] = std::atan2(d.dot(w), d.dot(u));
  }
  // Bins start half a bin before the first used vertex, so that the evenly spaced cross
  // sections of a generated ring fall in the middle of bins, not on their edges.
  double start = 0;
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (used[v]) {
      start = angle[v];
      break;
    }
  // A coarse ring (16 cross sections) leaves some of 32 bins empty: halve the bins until each
  // holds a vertex. Each loop point is then the mean of whole cross sections, which stays
  // inside the tube as long as the ring has at least 8 of them.
  RingBins out;
  out.of_vertex.assign(static_cast<size_t>(V.rows()), -1);
  for (int n = bins; n >= 8; n /= 2) {
    std::vector<int> count(n, 0);
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
      if (!used[v]) continue;
      double turn = (angle[v] - start) / (2 * M_PI) + 0.5 / n;
      turn -= std::floor(turn);
      const int k = std::clamp(static_cast<int>(std::floor(turn * n)), 0, n - 1);
      out.of_vertex[static_cast<size_t>(v)] = k;
      ++count[k];
    }
    if (std::find(count.begin(), count.end(), 0) != count.end()) continue;
    out.count = n;
    return out;
  }
  return std::nullopt;
}

Loop loop_from_bins(const MatrixX3d& V, const RingBins& bins) {
  MQ_CHECK(static_cast<Eigen::Index>(bins.of_vertex.size()) == V.rows(), InvalidInput,
           "loop_from_bins: ", bins.of_vertex.size(), " bins for ", V.rows(), " vertices");
  std::vector<Vector3d> sum(static_cast<size_t>(bins.count), Vector3d::Zero());
  std::vector<int> count(static_cast<size_t>(bins.count), 0);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const int k = bins.of_vertex[static_cast<size_t>(v)];
    if (k < 0) continue;
    sum[k] += V.row(v).transpose();
    ++count[k];
  }
  Loop loop(static_cast<size_t>(bins.count));
  for (int k = 0; k < bins.count; ++k) loop[k] = sum[k] / std::max(count[k], 1);
  return loop;
}

namespace {

// Best-fit plane of points: eigenvalues ascending, so col(0) is the normal.
Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread(const Vector3d* begin, const Vector3d* end,
                                                      Vector3d& mean) {
  mean = Vector3d::Zero();
  for (const Vector3d* p = begin; p != end; ++p) mean += *p;
  mean /= static_cast<double>(end - begin);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vector3d* p = begin; p != end; ++p) cov += (*p - mean) * (*p - mean).transpose();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov);
}

bool inside_polygon(const std::vector<Vector2d>& poly, const Vector2d& c) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vector2d& a = poly[i];
    const Vector2d& b = poly[j];
    if ((a.y() > c.y()) != (b.y() > c.y()) &&
        c.x() < a.x() + (c.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()))
      in = !in;
  }
  return in;
}

double distance_to_polygon(const std::vector<Vector2d>& poly, const Vector2d& c) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vector2d ab = poly[i] - poly[j];
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? std::clamp((c - poly[j]).dot(ab) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, (poly[j] + t * ab - c).squaredNorm());
  }
  return std::sqrt(best);
}

double distance_to_segment(const Vector2d& c, const Vector2d& a, const Vector2d& b) {
  const Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((c - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - c).norm();
}

// Compass search from c for the largest value of `clearance`, staying inside the loop: steps
// from half the loop's inner radius down to a thousandth of it.
template <typename Clearance>
double climb(const std::vector<Vector2d>& poly, double pole, Vector2d& c, Clearance clearance) {
  double best = clearance(c);
  for (double step = 0.5 * pole; step > 1e-3 * pole;) {
    bool moved = false;
    for (const Vector2d& m :
         {Vector2d(step, 0), Vector2d(-step, 0), Vector2d(0, step), Vector2d(0, -step)}) {
      const Vector2d t = c + m;
      if (!inside_polygon(poly, t)) continue;
      const double d = clearance(t);
      if (d > best) {
        best = d;
        c = t;
        moved = true;
        break;
      }
    }
    if (!moved) step *= 0.5;
  }
  return best;
}

// The free hole's diameter. From the loop's pole (the point inside it farthest from its edges,
// found on a 16 x 16 grid) a compass search climbs the distance to the nearest projected vertex;
// the hole of a ring is one basin around its middle, so a local climb finds it. Vertices alone
// let the disk slip between the sections of a coarse ring (16 sections: a third of the radius
// apart) when its walls touch, so where the vertex figure, less the longest projected edge,
// comes under `exact_below`, the climb goes on with the distance to the projected edges.
//   edges  the element's edges as index pairs into points, each at least once
double free_opening(const std::vector<Vector2d>& poly, const std::vector<Vector2d>& points,
                    const std::vector<std::pair<int, int>>& edges, double exact_below) {
  Vector2d lo = poly[0], hi = poly[0];
  for (const Vector2d& p : poly) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  constexpr int kGrid = 16;
  Vector2d c = Vector2d::Zero();
  double pole = 0;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      const Vector2d t(lo.x() + (hi.x() - lo.x()) * (i + 0.5) / kGrid,
                       lo.y() + (hi.y() - lo.y()) * (j + 0.5) / kGrid);
      if (!inside_polygon(poly, t)) continue;
      const double d = distance_to_polygon(poly, t);
      if (d > pole) {
        pole = d;
        c = t;
      }
    }
  if (!(pole > 0) || points.empty()) return 0;
  const double by_vertices = climb(poly, pole, c, [&](const Vector2d& t) {
    double best = std::numeric_limits<double>::infinity();
    for (const Vector2d& q : points) best = std::min(best, (q - t).squaredNorm());
    return std::sqrt(best);
  });
  double longest = 0;
  for (const auto& [a, b] : edges) longest = std::max(longest, (points[a] - points[b]).norm());
  // Every point of an edge lies within half its length of an end.
  if (2 * by_vertices - longest >= exact_below) return 2 * by_vertices;
  return 2 * climb(poly, pole, c, [&](const Vector2d& t) {
           double best = std::numeric_limits<double>::infinity();
           for (const auto& [a, b] : edges)
             best = std::min(best, distance_to_segment(t, points[a], points[b]));
           return best;
         });
}

// RingShape::fold of a loop whose area-oriented plane normal is given.
double fold_of_halves(const Loop& loop, const Vector3d& normal) {
  const size_t n = loop.size();
  double fold = 0;
  // Halves of consecutive points: [s, s + h] and [s + h, s + n], sharing their end points. A
  // half that is nearly straight has no plane of its own and takes the loop's.
  const size_t h = n / 2;
  std::vector<Vector3d> half;
  const auto half_normal = [&](size_t from, size_t count) {
    half.clear();
    for (size_t k = 0; k <= count; ++k) half.push_back(loop[(from + k) % n]);
    Vector3d m;
    const auto e = spread(half.data(), half.data() + half.size(), m);
    if (!(e.eigenvalues()(1) > 1e-4 * e.eigenvalues()(2))) return normal;
    const Vector3d hn = e.eigenvectors().col(0);
    return hn.dot(normal) < 0 ? Vector3d(-hn) : hn;
  };
  for (size_t s = 0; s < h; ++s) {
    const Vector3d a = half_normal(s, h), b = half_normal(s + h, n - h);
    fold = std::max(fold, std::atan2(a.cross(b).norm(), a.dot(b)));
  }
  return fold;
}

// The loop's mean point and plane normal, turned along its area vector (the loop winds once
// around its mean point there: ring_centre_loop bins it so); u the plane's longest axis.
Vector3d loop_plane(const Loop& loop, Vector3d& mean, Vector3d* u) {
  const size_t n = loop.size();
  const auto eig = spread(loop.data(), loop.data() + n, mean);
  Vector3d normal = eig.eigenvectors().col(0);
  if (u) *u = eig.eigenvectors().col(2);
  Vector3d area_vector = Vector3d::Zero();
  for (size_t k = 0; k < n; ++k) area_vector += (loop[k] - mean).cross(loop[(k + 1) % n] - mean);
  if (area_vector.dot(normal) < 0) normal = -normal;
  return normal;
}

}  // namespace

RingShape ring_shape(const MatrixX3d& V, const MatrixX3i& F, const Loop& loop) {
  MQ_CHECK(loop.size() >= 4, InvalidInput, "ring_shape: a loop needs at least 4 points, got ",
           loop.size());
  MQ_CHECK(F.rows() == 0 || (F.minCoeff() >= 0 && F.maxCoeff() < V.rows()), InvalidInput,
           "ring_shape: a face index is out of range");
  RingShape out;
  const size_t n = loop.size();
  double length = 0;
  for (size_t k = 0; k < n; ++k) length += (loop[(k + 1) % n] - loop[k]).norm();
  double area = 0;
  std::vector<char> used(static_cast<size_t>(V.rows()), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
    for (int k = 0; k < 3; ++k) used[static_cast<size_t>(F(f, k))] = 1;
  }
  out.wire = length > 0 ? area / (M_PI * length) : 0;

  Vector3d mean, u;
  const Vector3d normal = loop_plane(loop, mean, &u);
  const Vector3d w = normal.cross(u);

  std::vector<Vector2d> poly(n), points;
  for (size_t k = 0; k < n; ++k) {
    const Vector3d d = loop[k] - mean;
    poly[k] = Vector2d(d.dot(u), d.dot(w));
  }
  std::vector<int> index(static_cast<size_t>(V.rows()), -1);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    if (!used[static_cast<size_t>(v)]) continue;
    const Vector3d d = V.row(v).transpose() - mean;
    index[static_cast<size_t>(v)] = static_cast<int>(points.size());
    points.emplace_back(d.dot(u), d.dot(w));
  }
  // Every face's edges (each edge twice: duplicates cost time only in the exact climb, which
  // few rings need; sorting them out cost more on every ring).
  std::vector<std::pair<int, int>> edges;
  edges.reserve(static_cast<size_t>(3 * F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      edges.emplace_back(index[static_cast<size_t>(F(f, k))],
                         index[static_cast<size_t>(F(f, (k + 1) % 3))]);
  // Exact where the figure decides (issue 23's criterion is one wire diameter), with a margin.
  out.opening = free_opening(poly, points, edges, 2 * out.wire);

  out.fold = fold_of_halves(loop, normal);
  return out;
}

double ring_fold(const Loop& loop) {
  MQ_CHECK(loop.size() >= 4, InvalidInput, "ring_fold: a loop needs at least 4 points, got ",
           loop.size());
  Vector3d mean;
  const Vector3d normal = loop_plane(loop, mean, nullptr);
  return fold_of_halves(loop, normal);
}

std::optional<Loop> ring_centre_loop(const MatrixX3d& V, const MatrixX3i& F, int bins) {
  const std::optional<RingBins> b = ring_loop_bins(V, F, bins);
  if (!b) return std::nullopt;
  return loop_from_bins(V, *b);
}

}  // namespace mq
