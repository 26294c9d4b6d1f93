#include "core/surface/vine_growth.h"

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <functional>
#include <memory>
#include <queue>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/quilt_elements.h"
#include "core/shell/offset_surface.h"
#include "core/shell/placement_check.h"
#include "core/shell/signed_height.h"

namespace mq {

namespace {

// --- the swatch ------------------------------------------------------------------------------

// Shortest-path distances along the edges of (V, adj) from `source`.
std::vector<double> graph_distances(const MatrixX3d& V, const Adjacency& adj, int source) {
  std::vector<double> dist(static_cast<size_t>(V.rows()), kInf);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  dist[static_cast<size_t>(source)] = 0;
  queue.emplace(0.0, source);
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[static_cast<size_t>(v)]) continue;
    for (const int* w = adj.begin(v); w != adj.end(v); ++w) {
      const double nd = d + (V.row(v) - V.row(*w)).norm();
      if (nd < dist[static_cast<size_t>(*w)]) {
        dist[static_cast<size_t>(*w)] = nd;
        queue.emplace(nd, *w);
      }
    }
  }
  return dist;
}

int farthest(const std::vector<double>& d) {
  int best = 0;
  for (size_t i = 0; i < d.size(); ++i)
    if (std::isfinite(d[i]) && d[i] > d[static_cast<size_t>(best)]) best = static_cast<int>(i);
  return best;
}

// An element's length as the structure measure takes it (core/structure/texture_structure): the
// double-sweep graph diameter, exact on a tube; its width the diameter of a tube of that length
// and the element's area.
struct ElementLength {
  double length = 0, width = 0;
  bool is_long = false;
};

ElementLength element_length(const Element& e) {
  ElementLength out;
  if (e.V.rows() < 2 || e.F.rows() == 0) return out;
  const Adjacency adj = vertex_adjacency(e.F, static_cast<int>(e.V.rows()));
  const int a = farthest(graph_distances(e.V, adj, 0));
  const std::vector<double> from_a = graph_distances(e.V, adj, a);
  out.length = from_a[static_cast<size_t>(farthest(from_a))];
  if (!(out.length > 0)) return out;
  out.width = surface_area(e.V, e.F) / (M_PI * out.length);
  out.is_long = out.length >= 4 * out.width;
  return out;
}

// The vine and what it carries, in the vine's straight frame: u along its principal axis, v to
// the left of it (v = z x u: the frame is right-handed like the stem's (tangent, normal x
// tangent, normal) on the surface), z the height.
struct SwatchLeaf {
  // #V by 3: (along, across, z) in the frame of the vine's centreline where it is attached (its
  // point and tangent there), z the height.
  MatrixX3d P;
  MatrixX3i F;
  int kind = 0;
  double attach = 0;  // where it sits along one swatch vine length, in [0, period]
  int element = 0;    // in the prepared swatch
};

struct VineModel {
  int kind = 0;
  double period = 0;        // the swatch vine's length along its axis
  double radius = 0;        // of its tube
  int segments = 8;         // around the tube
  double ring_spacing = 0;  // between its cross-sections
  // The centreline's lateral offset and height at u = i * step, i = 0..n-1, periodic with
  // period n * step: the swatch's own, with a cubic blend added so that its value and slope
  // at the end meet those at the start.
  double step = 0;
  std::vector<double> wave, lift;
  double extent = 0;               // max |wave| + radius: the tube's lateral reach from the axis
  double reach = 0;                // the farthest any element's vertex lies from the axis
  std::vector<SwatchLeaf> leaves;  // ascending attach
  // Where the stems come from in the swatch (SurfaceElement::source, for swatch animation): the
  // vine's element, its axis frame in the prepared swatch (footprint origin and unit axis), and
  // where it starts along the axis.
  int element = 0;
  Vector2d origin = Vector2d::Zero(), axis = Vector2d::UnitX();
  double u0 = 0;

  // A leaf's vertices in the stem's straight frame (arc length, lateral, height) when attached
  // at arc length x: moved with the stem's centreline there (its point and tangent), so that it
  // sits on the vine as in the swatch although the blend changed the wave.
  MatrixX3d pose(const SwatchLeaf& leaf, double x, double phase = 0) const {
    const double w = at(wave, x + phase), t = std::atan(slope(wave, x + phase));
    const double c = std::cos(t), s = std::sin(t);
    MatrixX3d out(leaf.P.rows(), 3);
    for (Eigen::Index i = 0; i < leaf.P.rows(); ++i)
      out.row(i) << x + c * leaf.P(i, 0) - s * leaf.P(i, 1),
          w + s * leaf.P(i, 0) + c * leaf.P(i, 1), leaf.P(i, 2);
    return out;
  }

  // Linear interpolation of the periodic samples and its central-difference slope.
  double at(const std::vector<double>& f, double s) const {
    const int n = static_cast<int>(f.size());
    double x = std::fmod(s / step, static_cast<double>(n));
    if (x < 0) x += n;
    const int i = std::min(n - 1, static_cast<int>(x));
    const double t = x - i;
    return (1 - t) * f[static_cast<size_t>(i)] + t * f[static_cast<size_t>((i + 1) % n)];
  }
  double slope(const std::vector<double>& f, double s) const {
    return (at(f, s + step) - at(f, s - step)) / (2 * step);
  }
};

// The vine's principal axis in the swatch plane: (origin, unit direction).
std::pair<Vector2d, Vector2d> principal_axis(const MatrixX3d& V) {
  const Vector2d c = V.leftCols<2>().colwise().mean().transpose();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Vector2d q = V.row(i).head<2>().transpose() - c;
    cov += q * q.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  Vector2d a = eig.eigenvectors().col(1);
  if (a.x() < 0 || (a.x() == 0 && a.y() < 0)) a = -a;  // deterministic sign
  return {c, a};
}

int find_vine(const PreparedSwatch& swatch, std::vector<ElementLength>* lengths) {
  const int n = static_cast<int>(swatch.elements.size());
  std::vector<ElementLength> len(static_cast<size_t>(n));
  int vine = -1, long_count = 0;
  for (int i = 0; i < n; ++i) {
    len[static_cast<size_t>(i)] = element_length(swatch.elements[static_cast<size_t>(i)]);
    if (len[static_cast<size_t>(i)].is_long) {
      ++long_count;
      vine = i;
    }
  }
  if (lengths) *lengths = std::move(len);
  return long_count == 1 ? vine : -1;
}

// The vine's straight frame in the swatch plane: (along its principal axis, to the left of it,
// height).
struct VineAxisFrame {
  Vector2d origin, axis, left;
  Vector3d operator()(const Vector3d& q) const {
    const Vector2d d = q.head<2>() - origin;
    return Vector3d(d.dot(axis), d.dot(left), q.z());
  }
};

VineAxisFrame vine_axis_frame(const MatrixX3d& V) {
  const auto [origin, axis] = principal_axis(V);
  return {origin, axis, Vector2d(-axis.y(), axis.x())};
}

// The tube's resolution as the swatch's: segments from the largest valence (a fan cap's centre
// has one per segment), cross-sections from the vertex count.
void set_vine_resolution(const Element& vine, VineModel& m) {
  const Eigen::Index nv = vine.V.rows();
  const Adjacency adj = vertex_adjacency(vine.F, static_cast<int>(nv));
  int valence = 0;
  for (int v = 0; v < adj.size(); ++v) valence = std::max(valence, adj.degree(v));
  m.segments = std::clamp(valence, 6, 32);
  const int rings =
      std::max(2, static_cast<int>(std::lround(static_cast<double>(nv - 2) / m.segments)));
  m.ring_spacing = std::clamp(m.period / (rings - 1), m.period / 2000, m.period / 4);
}

// The swatch vine's centreline in its frame, as it is (before the periodic blend): lateral
// offset v and height z at the slab borders u0 + i * width, i = 0..bins, linear between.
struct SwatchCentreline {
  double u0 = 0, u1 = 0, width = 0;
  int bins = 0;
  std::vector<double> v, z;  // bins + 1 nodes

  double lateral(double u) const {
    const double x = std::clamp((u - u0) / width, 0.0, static_cast<double>(bins));
    const int i = std::min(bins - 1, static_cast<int>(x));
    const double t = x - i;
    return (1 - t) * v[static_cast<size_t>(i)] + t * v[static_cast<size_t>(i) + 1];
  }
  double slope(double u) const {
    return (lateral(u + width) - lateral(u - width)) /
           (std::min(u + width, u1) - std::max(u - width, u0));
  }
};

// The centreline of the vine's vertices U (in its frame): their mean lateral offset and height
// in slabs across the axis about a cross-section wide, an empty slab interpolated between the
// nearest filled ones, each node the mean of the slabs on either side of it.
SwatchCentreline measure_centreline(const MatrixX3d& U, double u0, double u1, const VineModel& m) {
  SwatchCentreline c;
  c.u0 = u0;
  c.u1 = u1;
  const int bins = c.bins = std::max(4, static_cast<int>(std::lround(m.period / m.ring_spacing)));
  const double width = c.width = m.period / bins;
  std::vector<double> sv(static_cast<size_t>(bins), 0), sz(sv), count(sv);
  for (Eigen::Index i = 0; i < U.rows(); ++i) {
    const int b = std::clamp(static_cast<int>((U(i, 0) - u0) / width), 0, bins - 1);
    sv[static_cast<size_t>(b)] += U(i, 1);
    sz[static_cast<size_t>(b)] += U(i, 2);
    count[static_cast<size_t>(b)] += 1;
  }
  std::vector<double> bv(static_cast<size_t>(bins)), bz(bv);
  std::vector<int> filled;
  for (int b = 0; b < bins; ++b)
    if (count[static_cast<size_t>(b)] > 0) {
      bv[static_cast<size_t>(b)] = sv[static_cast<size_t>(b)] / count[static_cast<size_t>(b)];
      bz[static_cast<size_t>(b)] = sz[static_cast<size_t>(b)] / count[static_cast<size_t>(b)];
      filled.push_back(b);
    }
  MQ_CHECK(!filled.empty(), InvalidInput, "the swatch's vine has no vertices");
  for (int b = 0; b < bins; ++b) {
    if (count[static_cast<size_t>(b)] > 0) continue;
    // Empty slab: interpolated between the nearest filled ones.
    const auto hi = std::lower_bound(filled.begin(), filled.end(), b);
    const int r = hi == filled.end() ? filled.back() : *hi;
    const int l = hi == filled.begin() ? filled.front() : *(hi - 1);
    const double t = r == l ? 0 : static_cast<double>(b - l) / (r - l);
    bv[static_cast<size_t>(b)] =
        (1 - t) * bv[static_cast<size_t>(l)] + t * bv[static_cast<size_t>(r)];
    bz[static_cast<size_t>(b)] =
        (1 - t) * bz[static_cast<size_t>(l)] + t * bz[static_cast<size_t>(r)];
  }
  // Nodes at the slab borders u0 + i * width, i = 0..bins.
  c.v.resize(static_cast<size_t>(bins) + 1);
  c.z.resize(static_cast<size_t>(bins) + 1);
  for (int i = 0; i <= bins; ++i) {
    const int a = std::max(0, i - 1), b = std::min(bins - 1, i);
    c.v[static_cast<size_t>(i)] = 0.5 * (bv[static_cast<size_t>(a)] + bv[static_cast<size_t>(b)]);
    c.z[static_cast<size_t>(i)] = 0.5 * (bz[static_cast<size_t>(a)] + bz[static_cast<size_t>(b)]);
  }
  return c;
}

// The tube's radius: the median distance of the vine's vertices U from the centreline polyline.
double tube_radius(const MatrixX3d& U, const SwatchCentreline& c) {
  const Eigen::Index nv = U.rows();
  const int bins = c.bins;
  const double u0 = c.u0, width = c.width;
  std::vector<double> d(static_cast<size_t>(nv));
  for (Eigen::Index i = 0; i < nv; ++i) {
    const Vector3d q = U.row(i).transpose();
    const int b = std::clamp(static_cast<int>((q.x() - u0) / width), 0, bins - 1);
    double best = kInf;
    for (int k = std::max(0, b - 2); k <= std::min(bins - 1, b + 2); ++k) {
      const Vector3d a(u0 + k * width, c.v[static_cast<size_t>(k)], c.z[static_cast<size_t>(k)]);
      const Vector3d e1(u0 + (k + 1) * width, c.v[static_cast<size_t>(k) + 1],
                        c.z[static_cast<size_t>(k) + 1]);
      const Vector3d e = e1 - a;
      const double t = std::clamp((q - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + t * e - q).norm());
    }
    d[static_cast<size_t>(i)] = best;
  }
  std::nth_element(d.begin(), d.begin() + nv / 2, d.end());
  return d[static_cast<size_t>(nv / 2)];
}

// The periodic blend h of the centreline nodes f (cubic Hermite in t = u / period): h(0) =
// h'(0) = 0, and at the end h = f(0) - f(P), h' = f'(0) - f'(P), so that f + h joins itself
// with value and slope.
class PeriodicBlend {
 public:
  PeriodicBlend(const std::vector<double>& f, int bins, double width)
      : f0_(f.front()),
        f1_(f.back()),
        s0_((f[1] - f[0]) / width),
        s1_((f[static_cast<size_t>(bins)] - f[static_cast<size_t>(bins) - 1]) / width),
        bins_(bins),
        width_(width) {}
  double operator()(double u) const {
    const double t = std::clamp(u / (bins_ * width_), 0.0, 1.0);
    return (f0_ - f1_) * (3 * t * t - 2 * t * t * t) +
           (s0_ - s1_) * bins_ * width_ * (t * t * t - t * t);
  }

 private:
  double f0_, f1_, s0_, s1_;
  int bins_;
  double width_;
};

// The model's periodic wave and lift (the centreline plus its blend, sampled at the nodes) and
// the tube's lateral reach from the axis.
void set_periodic_centreline(const SwatchCentreline& c, const PeriodicBlend& hv,
                             const PeriodicBlend& hz, VineModel& m) {
  const int bins = c.bins;
  const double width = c.width;
  m.step = width;
  m.wave.resize(static_cast<size_t>(bins));
  m.lift.resize(static_cast<size_t>(bins));
  for (int i = 0; i < bins; ++i) {
    m.wave[static_cast<size_t>(i)] = c.v[static_cast<size_t>(i)] + hv(i * width);
    m.lift[static_cast<size_t>(i)] = c.z[static_cast<size_t>(i)] + hz(i * width);
  }
  for (const double w : m.wave) m.extent = std::max(m.extent, std::abs(w) + m.radius);
  m.reach = m.extent;
}

// Where an element meets the vine, along one swatch vine length: at its vertex nearest the
// swatch's centreline (laterally).
double leaf_attachment(const Element& el, const VineAxisFrame& frame, const SwatchCentreline& c) {
  double attach = 0, nearest = kInf;
  for (Eigen::Index i = 0; i < el.V.rows(); ++i) {
    const Vector3d q = frame(el.V.row(i).transpose());
    const double d = std::abs(q.y() - c.lateral(q.x()));
    if (d < nearest) {
      nearest = d;
      attach = std::clamp(q.x(), c.u0, c.u1) - c.u0;
    }
  }
  return attach;
}

// A leaf's vertices (el's) in the vine's straight frame at its attach point, as in the swatch:
// relative to the swatch's centreline (before the blend) and its slope there.
void pose_swatch_leaf(const Element& el, const VineAxisFrame& frame, const SwatchCentreline& c,
                      const PeriodicBlend& hz, SwatchLeaf& leaf) {
  leaf.F = el.F;
  leaf.P.resize(el.V.rows(), 3);
  const double ua = c.u0 + leaf.attach, va = c.lateral(ua), t = std::atan(c.slope(ua));
  const double cs = std::cos(t), s = std::sin(t);
  for (Eigen::Index i = 0; i < el.V.rows(); ++i) {
    const Vector3d q = frame(el.V.row(i).transpose());
    const double du = q.x() - ua, dv = q.y() - va;
    // Heights follow the blended centreline's (the vine's lift changes little along it).
    leaf.P.row(i) << cs * du + s * dv, -s * du + cs * dv, std::max(0.0, q.z() + hz(leaf.attach));
  }
}

// The other elements as the vine's leaves, relative to where they meet it, and the farthest
// any reaches from the axis. detailed (optional): the lower-detail swatch, whose leaves are
// placed where the full ones sit (the reach stays the full run's).
void add_swatch_leaves(const PreparedSwatch& swatch, int vine_index, const VineAxisFrame& frame,
                       const SwatchCentreline& c, const PeriodicBlend& hz,
                       const PreparedSwatch* detailed, VineModel& m) {
  for (size_t e = 0; e < swatch.elements.size(); ++e) {
    if (static_cast<int>(e) == vine_index) continue;
    const Element& el = swatch.elements[e];
    SwatchLeaf leaf;
    leaf.kind = el.kind;
    leaf.element = static_cast<int>(e);
    leaf.attach = leaf_attachment(el, frame, c);
    pose_swatch_leaf(el, frame, c, hz, leaf);
    m.reach = std::max(m.reach, m.pose(leaf, leaf.attach).col(1).cwiseAbs().maxCoeff());
    // At lower detail: the simplified leaf where the full one sits (the reach and the spacing
    // stay the full run's).
    if (detailed) pose_swatch_leaf(detailed->elements[e], frame, c, hz, leaf);
    m.leaves.push_back(std::move(leaf));
  }
}

// The vine of `swatch` (at full detail: its centreline and leaf positions are measured there).
// detailed (optional): the swatch at lower detail (core/mesh/element_detail.h, same element
// order): the leaves take its geometry, placed as the full ones, and the stem's tube its share
// of faces (as many fewer sides as cross-sections).
VineModel analyse_vine(const PreparedSwatch& swatch, int vine_index,
                       const PreparedSwatch* detailed = nullptr) {
  const Element& vine = swatch.elements[static_cast<size_t>(vine_index)];
  VineModel m;
  m.kind = vine.kind;
  const VineAxisFrame frame = vine_axis_frame(vine.V);
  const Eigen::Index nv = vine.V.rows();
  MatrixX3d U(nv, 3);
  for (Eigen::Index i = 0; i < nv; ++i) U.row(i) = frame(vine.V.row(i).transpose()).transpose();
  const double u0 = U.col(0).minCoeff(), u1 = U.col(0).maxCoeff();
  m.period = u1 - u0;
  m.element = vine_index;
  m.origin = frame.origin;
  m.axis = frame.axis;
  m.u0 = u0;
  MQ_CHECK(m.period > 0, InvalidInput, "the swatch's vine has no length");
  set_vine_resolution(vine, m);
  const SwatchCentreline centre = measure_centreline(U, u0, u1, m);
  m.radius = tube_radius(U, centre);
  MQ_CHECK(m.radius > 0, InvalidInput, "the swatch's vine has no thickness");
  const PeriodicBlend hv(centre.v, centre.bins, centre.width),
      hz(centre.z, centre.bins, centre.width);
  set_periodic_centreline(centre, hv, hz, m);
  add_swatch_leaves(swatch, vine_index, frame, centre, hz, detailed, m);
  if (detailed) {
    // The stem's faces go as segments / ring_spacing: both by the square root of the share.
    const double share = static_cast<double>(detailed->elements[vine_index].F.rows()) /
                         static_cast<double>(vine.F.rows());
    const double k = std::sqrt(std::min(1.0, share));
    m.segments = std::max(6, static_cast<int>(std::lround(m.segments * k)));
    m.ring_spacing = std::min(m.period / 4, m.ring_spacing / k);
  }
  return m;
}

// --- walking on the base -----------------------------------------------------------------------

struct SurfacePoint {
  int face = -1;
  Vector3d bary = Vector3d::Constant(1.0 / 3);
};

// The element size a size map asks for at a point of the base, as a factor of the swatch's
// (SurfaceJob::log_size, its log interpolated over the face so that a stem's tube and its
// leaves change size smoothly along it); 1 without a map (issue 25).
class SizeField {
 public:
  explicit SizeField(const SurfaceJob& job) : F_(job.base.F), log_size_(job.log_size) {}
  bool varies() const { return log_size_.size() > 0; }
  double operator()(const SurfacePoint& p) const {
    if (!varies()) return 1.0;
    double l = 0;
    for (int k = 0; k < 3; ++k) l += p.bary(k) * log_size_(F_(p.face, k));
    return std::exp(l);
  }
  // The smaller of the sizes at the base's vertices a and b.
  double at_edge(int a, int b) const {
    return varies() ? std::exp(std::min(log_size_(a), log_size_(b))) : 1.0;
  }

 private:
  const MatrixX3i& F_;
  const Eigen::VectorXd& log_size_;
};

// Straight lines on the surface: within a face a line, across an edge the direction carried over
// by unfolding the two faces into one plane (so it keeps its angle to the edge: a geodesic).
class SurfaceWalker {
 public:
  SurfaceWalker(const TriMesh& base, const MatrixX3i& TT)
      : V_(base.V), F_(base.F), TT_(TT), FN_(face_normals(base.V, base.F)) {}

  Vector3d position(const SurfacePoint& p) const {
    return p.bary(0) * V_.row(F_(p.face, 0)).transpose() +
           p.bary(1) * V_.row(F_(p.face, 1)).transpose() +
           p.bary(2) * V_.row(F_(p.face, 2)).transpose();
  }
  Vector3d normal(int f) const { return FN_.row(f).transpose(); }
  Vector3d centroid(int f) const {
    return (V_.row(F_(f, 0)) + V_.row(F_(f, 1)) + V_.row(F_(f, 2))).transpose() / 3.0;
  }
  const MatrixX3d& normals() const { return FN_; }

  // Moves p by `distance` along d (a unit vector in p's face plane), carrying d along. Returns
  // false when a boundary edge (or a non-manifold one) stops it first: p then lies on it.
  bool walk(SurfacePoint& p, Vector3d& d, double distance) const {
    double left = distance;
    int crossings = 0, stalled = 0;
    while (left > 0) {
      const Vector3d r = rate(p.face, d);
      double t = kInf;
      int exit = -1;
      for (int k = 0; k < 3; ++k)
        if (r(k) < 0) {
          const double tk = std::max(0.0, p.bary(k)) / -r(k);
          if (tk < t) t = tk, exit = k;
        }
      if (exit < 0 || t >= left) {
        p.bary = normalized(p.bary + left * r);
        return true;
      }
      p.bary += t * r;
      p.bary(exit) = 0;
      p.bary = normalized(p.bary);
      left -= t;
      // A point on a vertex can bounce between the faces around it without advancing: it is
      // nudged into its face.
      stalled = t > 0 ? 0 : stalled + 1;
      if (stalled > 8) {
        p.bary = normalized(0.999 * p.bary + Vector3d::Constant(0.001 / 3));
        stalled = 0;
        continue;
      }
      const int e = (exit + 1) % 3;  // the edge F(f,e)-F(f,e+1), opposite vertex `exit`
      const int g = TT_(p.face, e);
      if (g < 0 || ++crossings > 100000) return false;
      const int va = F_(p.face, e), vb = F_(p.face, (e + 1) % 3);
      const double wa = p.bary(e), wb = p.bary((e + 1) % 3);
      d = unfold(p.face, g, va, vb, d);
      Vector3d b = Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        if (F_(g, k) == va) b(k) = wa;
        if (F_(g, k) == vb) b(k) = wb;
      }
      p.face = g;
      p.bary = normalized(b);
    }
    return true;
  }

 private:
  static Vector3d normalized(Vector3d b) {
    b = b.cwiseMax(0.0);
    const double s = b.sum();
    return s > 0 ? Vector3d(b / s) : Vector3d::Constant(1.0 / 3);
  }
  // Change of the barycentric coordinates per unit move along d in face f.
  Vector3d rate(int f, const Vector3d& d) const {
    const Vector3d a = V_.row(F_(f, 0)), e0 = V_.row(F_(f, 1)).transpose() - a,
                   e1 = V_.row(F_(f, 2)).transpose() - a;
    const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
    const double den = d00 * d11 - d01 * d01;
    if (!(den > 0)) return Vector3d::Zero();
    const double x0 = d.dot(e0), x1 = d.dot(e1);
    const double v = (d11 * x0 - d01 * x1) / den, w = (d00 * x1 - d01 * x0) / den;
    return Vector3d(-v - w, v, w);
  }
  // d (in face f's plane) carried across the edge (va, vb) into face g's plane.
  Vector3d unfold(int f, int g, int va, int vb, const Vector3d& d) const {
    const Vector3d A = V_.row(va), B = V_.row(vb);
    const Vector3d e = (B - A).normalized();
    Vector3d mf = normal(f).cross(e), mg = normal(g).cross(e);
    if (mf.dot(centroid(f) - A) > 0) mf = -mf;  // out of f
    if (mg.dot(centroid(g) - A) < 0) mg = -mg;  // into g
    const Vector3d out = d.dot(e) * e + d.dot(mf) * mg;
    const double n = out.norm();
    return n > 0 ? Vector3d(out / n) : d;
  }

  const MatrixX3d& V_;
  const MatrixX3i& F_;
  const MatrixX3i& TT_;
  MatrixX3d FN_;
};

// Points in a uniform hash grid of cell `cell`; near() visits those in the cells a ball of
// radius <= cell around q meets.
class PointGrid {
 public:
  explicit PointGrid(double cell) : cell_(cell) {}
  void insert(int id, const Vector3d& p) { cells_[key(cell_of(p))].push_back(id); }
  template <class Visit>
  bool any(const Vector3d& q, Visit&& visit) const {
    const Eigen::Array3i c = cell_of(q);
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) {
          const auto it = cells_.find(key(c + Eigen::Array3i(x, y, z)));
          if (it == cells_.end()) continue;
          for (const int id : it->second)
            if (visit(id)) return true;
        }
    return false;
  }

 private:
  Eigen::Array3i cell_of(const Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static long long key(const Eigen::Array3i& c) {
    return (static_cast<long long>(c(0)) * 73856093LL) ^
           (static_cast<long long>(c(1)) * 19349663LL) ^
           (static_cast<long long>(c(2)) * 83492791LL);
  }
  double cell_;
  std::unordered_map<long long, std::vector<int>> cells_;
};

// Triangles placed so far, binned by their boxes, for the test whether a new element would
// intersect any.
class TriangleGrid {
 public:
  explicit TriangleGrid(double cell) : cell_(cell) {}
  // The owner of a placed triangle that one of (V, F) intersects, or -1.
  int intersects(const MatrixX3d& V, const MatrixX3i& F) const {
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
      const Vector3d lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
      const Eigen::Array3i l = cell_of(lo), h = cell_of(hi);
      for (int x = l(0); x <= h(0); ++x)
        for (int y = l(1); y <= h(1); ++y)
          for (int z = l(2); z <= h(2); ++z) {
            const auto it = cells_.find(key(x, y, z));
            if (it == cells_.end()) continue;
            for (const int t : it->second) {
              const Tri& o = tri(t);
              if ((o.lo.array() > hi.array()).any() || (o.hi.array() < lo.array()).any()) continue;
              if (triangles_intersect(a, b, c, o.p[0], o.p[1], o.p[2])) return o.owner;
            }
          }
    }
    return -1;
  }
  // Marks the faces of (V, F) that intersect a placed triangle (bad: #F flags).
  void mark_intersecting(const MatrixX3d& V, const MatrixX3i& F, std::vector<char>& bad) const {
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      if (bad[static_cast<size_t>(f)]) continue;
      MatrixX3i one(1, 3);
      one.row(0) = F.row(f);
      bad[static_cast<size_t>(f)] = intersects(V, one) >= 0;
    }
  }
  void insert(const MatrixX3d& V, const MatrixX3i& F, int owner) {
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      Tri t;
      t.owner = owner;
      for (int k = 0; k < 3; ++k) t.p[static_cast<size_t>(k)] = V.row(F(f, k)).transpose();
      t.lo = t.p[0].cwiseMin(t.p[1]).cwiseMin(t.p[2]);
      t.hi = t.p[0].cwiseMax(t.p[1]).cwiseMax(t.p[2]);
      const int id = size_;
      const Eigen::Array3i l = cell_of(t.lo), h = cell_of(t.hi);
      if (size_ % kChunk == 0) chunks_.emplace_back(new Tri[kChunk]);  // pages not touched
      chunks_.back()[static_cast<size_t>(size_ % kChunk)] = t;
      ++size_;
      for (int x = l(0); x <= h(0); ++x)
        for (int y = l(1); y <= h(1); ++y)
          for (int z = l(2); z <= h(2); ++z) cells_[key(x, y, z)].push_back(id);
    }
  }

 private:
  struct Tri {
    std::array<Vector3d, 3> p;
    Vector3d lo, hi;
    int owner;
  };
  Eigen::Array3i cell_of(const Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static long long key(int x, int y, int z) {
    return (static_cast<long long>(x) * 73856093LL) ^ (static_cast<long long>(y) * 19349663LL) ^
           (static_cast<long long>(z) * 83492791LL);
  }
  // Stored in chunks that never move: a growing vector copied its ~1M triangles over and over
  // (ivy wall: 0.6 s of the leaves and stems, most of it faulting in the new copies' pages).
  // A chunk is 32 MiB, which glibc maps on its own and gives back when freed (smaller ones
  // stayed in the heap: the ivy wall's peak memory rose 100 MB); a Tri's constructor writes
  // nothing, so only the pages used are touched.
  static constexpr int kChunk = 1 << 18;
  const Tri& tri(int t) const {
    return chunks_[static_cast<size_t>(t / kChunk)][static_cast<size_t>(t % kChunk)];
  }
  double cell_;
  std::vector<std::unique_ptr<Tri[]>> chunks_;
  int size_ = 0;
  std::unordered_map<long long, std::vector<int>> cells_;
};

// --- evenly spaced streamlines -----------------------------------------------------------------

// Under a size map (SizeField) a line is traced in steps of the step option times the size
// where each step starts, so that its pattern coordinate t (arc length over the size: where the
// swatch's pattern is along it, in full-size units) advances by the step option each step;
// without a map t = s.
struct Sample {
  SurfacePoint point;
  Vector3d position, direction, normal;  // direction: the stem's, forwards
  double s = 0;                          // arc length along its line
  double t = 0;                          // pattern coordinate along its line
  double size = 1;                       // the size asked here (SizeField)
  int line = -1;
};

// Distances at full size: under a size map each is taken times the size where it is measured.
struct StreamlineOptions {
  double step = 0;            // between samples
  double separation = 0;      // d_sep: seeds this far from their line
  double seed_clearance = 0;  // a seed needs no sample (of any line) closer than this
  double stop = 0;            // d_test: a line ends this close to another
  double self_gap = 0;        // samples of its own line nearer along it than this do not stop it
  double obstacle = 0;        // a line ends this close to the base's boundary
  double turn_radius = 0;
  double min_length = 0;
  Vector3d up = Vector3d::UnitY();  // unit: seeds lowest along it first, patterns anchored on it
};

struct Seed {
  SurfacePoint point;
  int parent_sample = -1;  // the sample of the line beside which it lies, or -1
};

// Jobard and Lefer's placement on the base: lines are traced both ways from a seed until they
// come near another line (or their own, further along it), a boundary, or a place where the
// field turns against them; seeds are taken beside each finished line at the separation, then,
// when none is left, at the lowest face centre (along `up`) that no line is near, so that the
// stems grow from the bottom as ivy does.
class Streamlines {
 public:
  Streamlines(const SurfaceWalker& walker, const SizeField& size, const MatrixX3d& guide,
              const MatrixX3d& fallback, const std::vector<Vector3d>& obstacles,
              const StreamlineOptions& o)
      : walker_(walker),
        size_(size),
        guide_(guide),
        fallback_(fallback),
        o_(o),
        grid_(std::max(o.stop, o.seed_clearance)),
        obstacle_grid_(std::max(o.obstacle, 1e-12)),
        obstacles_(obstacles) {
    for (size_t i = 0; i < obstacles_.size(); ++i)
      obstacle_grid_.insert(static_cast<int>(i), obstacles_[i]);
  }

  void grow(const std::vector<int>& seed_faces, ProgressSink* progress) {
    std::deque<Seed> queue;
    for (size_t k = 0; k < seed_faces.size(); ++k) {
      Seed seed;
      seed.point.face = seed_faces[k];
      if ((k & 1023) == 0)
        report_progress(progress, Stage::Streamlines, static_cast<double>(k),
                        static_cast<double>(seed_faces.size()));
      if (!free_at(seed.point)) continue;
      nearest_line(seed);
      if (!trace_from(seed)) continue;
      beside(static_cast<int>(lines_.size()) - 1, queue);
      while (!queue.empty()) {
        const Seed q = queue.front();
        queue.pop_front();
        if (free_at(q.point) && trace_from(q)) beside(static_cast<int>(lines_.size()) - 1, queue);
      }
    }
  }

  // The kept lines, each its samples in order along it (s and t from 0), and its phase: the
  // pattern coordinate its swatch pattern starts at. A line seeded beside a parallel one continues
  // that one's phase at the seed, so that neighbours grown side by side carry their leaves at
  // matching places along them and the leaves of one interleave with the next's (as parallel
  // lines from one seed row do on a plane); another starts its pattern at the seed's height
  // along `up`, which is the same thing for lines that climb straight up.
  std::vector<std::pair<std::vector<Sample>, double>> lines() const {
    std::vector<double> start(lines_.size()), phase(lines_.size(), 0.0);
    for (size_t l = 0; l < lines_.size(); ++l) {
      start[l] = samples_[static_cast<size_t>(lines_[l].front())].t;
      const Origin& o = origin_[l];
      phase[l] = o.parent >= 0 ? (o.parent_t - start[static_cast<size_t>(o.parent)]) +
                                     phase[static_cast<size_t>(o.parent)] + start[l]
                               : o.anchor + start[l];
    }
    std::vector<std::pair<std::vector<Sample>, double>> out;
    for (size_t l = 0; l < lines_.size(); ++l) {
      if (!alive_[l]) continue;
      std::vector<Sample> line;
      for (const int id : lines_[l]) line.push_back(samples_[static_cast<size_t>(id)]);
      const double s0 = line.front().s;
      for (Sample& q : line) q.s -= s0, q.t -= start[l];
      out.emplace_back(std::move(line), phase[l]);
    }
    return out;
  }
  int short_lines() const { return short_; }

 private:
  // Whether a sample of another line (or of `line` farther along it than the self gap) lies
  // within `distance` (at full size) of q, taken at the mean of the sizes at q and at the sample:
  // neighbours of different sizes each keep half of the room between them.
  bool near_line(const Vector3d& q, const Vector3d& n, double distance, double size, int line,
                 double t) const {
    return grid_.any(q, [&](int id) {
      const Sample& o = samples_[static_cast<size_t>(id)];
      if (!alive_[static_cast<size_t>(o.line)]) return false;
      // The other side of a thin wall is no neighbour: its texture grows away from this.
      if (o.normal.dot(n) < -0.5) return false;
      if (o.line == line && std::abs(o.t - t) <= o_.self_gap) return false;
      const double radius = distance * (0.5 * (size + o.size));
      return (o.position - q).squaredNorm() < radius * radius;
    });
  }
  bool near_obstacle(const Vector3d& q, double size) const {
    const double r = o_.obstacle * size;
    return obstacle_grid_.any(
        q, [&](int id) { return (obstacles_[static_cast<size_t>(id)] - q).squaredNorm() < r * r; });
  }
  bool free_at(const SurfacePoint& p) const {
    const Vector3d q = walker_.position(p);
    const double size = size_(p);
    return !near_line(q, walker_.normal(p.face), o_.seed_clearance, size, -1, 0) &&
           !near_obstacle(q, size);
  }

  Vector3d start_direction(int f) const {
    const Vector3d n = walker_.normal(f);
    Vector3d g = guide_.row(f).transpose();
    if (g.norm() < 0.3) g = fallback_.row(f).transpose();  // the field is weak here
    g -= g.dot(n) * n;
    if (!(g.norm() > 0)) g = n.unitOrthogonal();
    return g.normalized();
  }

  int add(const SurfacePoint& p, const Vector3d& direction, double s, double t, double size,
          int line) {
    Sample q;
    q.point = p;
    q.position = walker_.position(p);
    q.normal = walker_.normal(p.face);
    q.direction = direction;
    q.s = s;
    q.t = t;
    q.size = size;
    q.line = line;
    samples_.push_back(q);
    const int id = static_cast<int>(samples_.size()) - 1;
    grid_.insert(id, q.position);
    return id;
  }

  // One half of a line: from p along sign * field. Returns the sample ids in order of tracing.
  std::vector<int> trace(SurfacePoint p, Vector3d d, double sign, int line) {
    std::vector<int> ids;
    double s = 0, t = 0, size = size_(p);
    const double max_length = 1e6 * o_.step;  // a guard only: lines end near others first
    while (t < max_length) {
      const int f = p.face;
      const Vector3d n = walker_.normal(f);
      const Vector3d g = sign * guide_.row(f).transpose();
      const double strength = g.norm();
      if (strength > 1e-12) {
        const Vector3d gh = g / strength;
        const double angle = std::atan2(n.dot(d.cross(gh)), d.dot(gh));
        // The field turns against the line (over the top of a wall, down its back): it ends.
        if (std::abs(angle) > 0.75 * M_PI && strength > 0.5) break;
        // The turn radius scales with the size as the step does.
        const double limit = strength * o_.step / o_.turn_radius;
        const double turn = std::clamp(angle, -limit, limit);
        d = std::cos(turn) * d + std::sin(turn) * n.cross(d);
        d -= d.dot(n) * n;
        d.normalize();
      }
      if (!walker_.walk(p, d, o_.step * size)) break;
      s += o_.step * size;
      t += o_.step;
      size = size_(p);
      const Vector3d q = walker_.position(p);
      if (near_line(q, walker_.normal(p.face), o_.stop, size, line, sign * t) ||
          near_obstacle(q, size))
        break;
      ids.push_back(add(p, sign > 0 ? d : Vector3d(-d), sign * s, sign * t, size, line));
    }
    return ids;
  }

  // The line nearest to a seed that no line placed (within the grid's reach) and running
  // along the field there, as its parent.
  void nearest_line(Seed& seed) const {
    const Vector3d q = walker_.position(seed.point), n = walker_.normal(seed.point.face);
    const Vector3d d = start_direction(seed.point.face);
    double best = kInf;
    grid_.any(q, [&](int id) {
      const Sample& o = samples_[static_cast<size_t>(id)];
      const double dist = (o.position - q).squaredNorm();
      if (alive_[static_cast<size_t>(o.line)] && o.normal.dot(n) >= -0.5 &&
          o.direction.dot(d) > kParallel &&
          (dist < best || (dist == best && id < seed.parent_sample))) {
        best = dist;
        seed.parent_sample = id;
      }
      return false;
    });
  }

  bool trace_from(const Seed& seed_in) {
    const SurfacePoint& seed = seed_in.point;
    const int line = static_cast<int>(lines_.size());
    lines_.emplace_back();
    alive_.push_back(1);
    const Vector3d d = start_direction(seed.face);
    Origin origin;
    const double size = size_(seed);
    origin.anchor = walker_.position(seed).dot(o_.up) / size;
    if (seed_in.parent_sample >= 0) {
      const Sample& p = samples_[static_cast<size_t>(seed_in.parent_sample)];
      if (p.direction.dot(d) > kParallel) origin.parent = p.line, origin.parent_t = p.t;
    }
    origin_.push_back(origin);
    const int first = add(seed, d, 0, 0, size, line);
    std::vector<int> back = trace(seed, -d, -1, line);
    const std::vector<int> ahead = trace(seed, d, 1, line);
    std::vector<int>& ids = lines_.back();
    ids.assign(back.rbegin(), back.rend());
    ids.push_back(first);
    ids.insert(ids.end(), ahead.begin(), ahead.end());
    // In pattern units: a line is long enough for as many swatch vines whatever its size.
    const double length = o_.step * static_cast<double>(ids.size() - 1);
    if (length < o_.min_length) {
      alive_.back() = 0;  // its samples stay in the grid, ignored
      ++short_;
      return false;
    }
    return true;
  }

  // Seeds at the separation on both sides of a line, about every half separation along it
  // (under a size map at the mean of the sizes at the line and at the seed).
  void beside(int line, std::deque<Seed>& queue) const {
    const std::vector<int>& ids = lines_[static_cast<size_t>(line)];
    const int every = std::max(1, static_cast<int>(0.5 * o_.separation / o_.step));
    for (size_t i = 0; i < ids.size(); i += static_cast<size_t>(every))
      for (const double side : {1.0, -1.0}) {
        const Sample& q = samples_[static_cast<size_t>(ids[i])];
        SurfacePoint p = q.point;
        Vector3d d = side * q.normal.cross(q.direction);
        bool free = walker_.walk(p, d, o_.separation * q.size);
        if (free && size_.varies()) {
          const double there = size_(p);
          p = q.point, d = side * q.normal.cross(q.direction);
          free = walker_.walk(p, d, o_.separation * 0.5 * (q.size + there));
        }
        if (free) {
          Seed seed;
          seed.point = p;
          seed.parent_sample = ids[i];
          queue.push_back(seed);
        }
      }
  }

  const SurfaceWalker& walker_;
  const SizeField& size_;
  const MatrixX3d& guide_;
  const MatrixX3d& fallback_;
  StreamlineOptions o_;
  std::vector<Sample> samples_;
  std::vector<std::vector<int>> lines_;
  std::vector<char> alive_;
  struct Origin {
    int parent = -1;      // the parallel line it was seeded beside, or -1
    double parent_t = 0;  // where, along the parent, as traced (pattern coordinate)
    double anchor = 0;    // the seed's height along `up`, over the size there
  };
  static constexpr double kParallel = 0.866;  // within 30 degrees
  std::vector<Origin> origin_;
  PointGrid grid_, obstacle_grid_;
  const std::vector<Vector3d>& obstacles_;
  int short_ = 0;
};

// --- elements along a stem ---------------------------------------------------------------------

// A stem's frame: arc length X along its streamline, lateral Y to its left; the swatch's
// pattern is laid along it by the pattern coordinate t (Sample).
class StemFrame {
 public:
  StemFrame(const SurfaceWalker& walker, const std::vector<Sample>& line, bool sized)
      : walker_(walker), line_(line), sized_(sized) {}
  double length() const { return line_.back().s; }
  double pattern_length() const { return line_.back().t; }

  // The point at pattern coordinate t (clamped to the line), the line's direction there and the
  // size asked there (*size; 1 without a size map).
  SurfacePoint at_pattern(double t, Vector3d& direction, double* size) const {
    if (!sized_) {
      *size = 1;
      return at(t, direction);
    }
    t = std::clamp(t, 0.0, pattern_length());
    const size_t i = sample_before(t, &Sample::t);
    SurfacePoint p = line_[i].point;
    direction = line_[i].direction;
    // The step from sample i was taken at its size (Streamlines::trace).
    walker_.walk(p, direction, (t - line_[i].t) * line_[i].size);
    *size = size_at(i, t);
    return p;
  }

  // The point at arc length x (clamped to the line) and the line's direction there.
  SurfacePoint at(double x, Vector3d& direction) const {
    x = std::clamp(x, 0.0, length());
    const size_t i = sample_before(x, &Sample::s);
    SurfacePoint p = line_[i].point;
    direction = line_[i].direction;
    walker_.walk(p, direction, x - line_[i].s);
    return p;
  }
  // The point reached from `from` (direction `direction` there) by the offset (dx, dy) in the
  // tangent plane (dx along the direction, dy to its left), along the surface. *whole (if
  // given) is cleared when the base's boundary cut the way short.
  SurfacePoint offset(SurfacePoint from, const Vector3d& direction, double dx, double dy,
                      bool* whole = nullptr) const {
    const Vector3d n = walker_.normal(from.face);
    const Vector3d v = dx * direction + dy * n.cross(direction);
    const double len = v.norm();
    if (len > 0) {
      Vector3d d = v / len;
      if (!walker_.walk(from, d, len) && whole) *whole = false;
    }
    return from;
  }

 private:
  // The last sample whose `key` (s or t) is at most `value` (the first when none is).
  size_t sample_before(double value, double Sample::*key) const {
    const auto after = std::upper_bound(line_.begin(), line_.end(), value,
                                        [key](double v, const Sample& q) { return v < q.*key; });
    const size_t i = static_cast<size_t>(after - line_.begin());
    return i == 0 ? 0 : i - 1;
  }
  // The size at t, between samples i and i + 1: interpolated, so that the tube has no steps.
  double size_at(size_t i, double t) const {
    if (i + 1 >= line_.size() || !(line_[i + 1].t > line_[i].t)) return line_[i].size;
    const double w = std::clamp((t - line_[i].t) / (line_[i + 1].t - line_[i].t), 0.0, 1.0);
    return (1 - w) * line_[i].size + w * line_[i + 1].size;
  }

  const SurfaceWalker& walker_;
  const std::vector<Sample>& line_;
  bool sized_;
};

// An element placed on the base: local coordinates and its 3D positions by normal displacement
// (for the intersection tests).
struct Placed {
  SurfaceElement element;
  MatrixX3d position;
};

// Where the embedding's normal displacement puts a point: over the refined base along the
// shell's smoothed directions (core/shell/offset_surface's displacement_directions, as
// core/shell/quilt_embedding). The shell map, where there is one, differs from it by a fraction of
// the shell height.
class Displacement {
 public:
  Displacement(const TriMesh& base, double shell_height)
      : base_(base), N_(displacement_directions(base.V, base.F, shell_height)) {}
  Vector3d operator()(int face, const Vector3d& b, double height) const {
    return displace_along_normal(base_, N_, face, b, height);
  }

 private:
  const TriMesh& base_;
  MatrixX3d N_;
};

void set_vertex(Placed& out, int v, const SurfacePoint& p, double height,
                const Displacement& shell) {
  out.element.face[static_cast<size_t>(v)] = p.face;
  out.element.barycentric.row(v) = p.bary.transpose();
  out.element.height(v) = height;
  out.position.row(v) = shell(p.face, p.bary, height).transpose();
}

// A stem of length S in its straight frame (arc length, lateral, height): the swatch vine's
// cross-section swept along its periodic centreline from pattern coordinate `phase`, capped
// at both ends. ring[v]: the arc length of vertex v's cross-section centre.
TriMesh stem_in_frame(const VineModel& m, double S, double phase, std::vector<double>* ring) {
  const int rings = std::max(2, static_cast<int>(std::ceil(S / m.ring_spacing)) + 1);
  const int seg = m.segments;
  TriMesh t;
  t.V.resize(rings * seg + 2, 3);
  if (ring) ring->assign(static_cast<size_t>(t.V.rows()), 0.0);
  for (int j = 0; j < rings; ++j) {
    const double s = S * j / (rings - 1);
    const double u = s + phase;  // along the swatch's pattern
    const Vector3d centre(s, m.at(m.wave, u), m.at(m.lift, u));
    const Vector3d T = Vector3d(1, m.slope(m.wave, u), m.slope(m.lift, u)).normalized();
    // The cross-section frame of the swatch generator's tubes: side = z x T, up = T x side.
    const Vector3d side = Vector3d::UnitZ().cross(T).normalized(), up = T.cross(side);
    for (int k = 0; k < seg; ++k) {
      const double phi = kTwoPi * k / seg;
      t.V.row(j * seg + k) =
          (centre + m.radius * (std::cos(phi) * side + std::sin(phi) * up)).transpose();
      if (ring) (*ring)[static_cast<size_t>(j * seg + k)] = s;
    }
    if (j == 0 || j == rings - 1) {
      const int c = rings * seg + (j == 0 ? 0 : 1);
      t.V.row(c) = centre.transpose();
      if (ring) (*ring)[static_cast<size_t>(c)] = s;
    }
  }
  t.F.resize(2 * (rings - 1) * seg + 2 * seg, 3);
  int f = 0;
  for (int j = 0; j + 1 < rings; ++j)
    for (int k = 0; k < seg; ++k) {
      const int k1 = (k + 1) % seg;
      const int a = j * seg + k, b = j * seg + k1, c = (j + 1) * seg + k1, d = (j + 1) * seg + k;
      t.F.row(f++) << a, b, c;
      t.F.row(f++) << a, c, d;
    }
  const int c0 = rings * seg, c1 = rings * seg + 1;
  for (int k = 0; k < seg; ++k) {
    const int k1 = (k + 1) % seg;
    t.F.row(f++) << c0, k1, k;
    t.F.row(f++) << c1, (rings - 1) * seg + k, (rings - 1) * seg + k1;
  }
  return t;
}

// The places along a stem of length S with pattern phase `phase` where the swatch's ratio puts
// a leaf: (arc length, leaf index), period by period along the stem; with `margin` > 0 also those
// up to that far past either end (a leaf there can still be moved onto the stem).
std::vector<std::pair<double, int>> leaf_slots(const VineModel& m, double S, double phase,
                                               double margin = 0) {
  std::vector<std::pair<double, int>> out;
  double first = std::fmod(phase, m.period);
  if (first < 0) first += m.period;
  for (int j = -1; j * m.period - first <= S + margin; ++j)
    for (size_t i = 0; i < m.leaves.size(); ++i) {
      const double x = m.leaves[i].attach + j * m.period - first;
      if (x >= -margin && x <= S + margin) out.emplace_back(x, static_cast<int>(i));
    }
  return out;
}

// The closest two straight stems side by side, in phase (as stems climbing a wall together
// are), can lie without touching: found by bisection on the swatch's own geometry laid out
// over a few periods in the stems' frame. Neighbours' leaves then interleave, each between two
// of the other's.
double parallel_spacing(const VineModel& m) {
  const double S = 4 * m.period;
  TriMesh one = stem_in_frame(m, S, 0, nullptr);
  for (const auto& [x, i] : leaf_slots(m, S, 0)) {
    TriMesh leaf;
    leaf.V = m.pose(m.leaves[static_cast<size_t>(i)], x);
    leaf.F = m.leaves[static_cast<size_t>(i)].F;
    append_mesh(one, leaf);
  }
  double lo = 2 * m.extent, hi = 2 * m.reach + m.extent;
  for (int it = 0; it < 24; ++it) {
    const double d = 0.5 * (lo + hi);
    TriMesh other = one;
    other.V.col(1).array() += d;
    (meshes_intersect(one, other) ? lo : hi) = d;
  }
  return hi;
}

// Where the vertex q of a stem (in its straight frame: arc length, lateral, height) with pattern
// phase `phase` comes from in the swatch (SurfaceElement::source): the straight frame laid along
// the swatch vine's axis, unwrapped (SurfaceQuilt::repeat says where along one swatch vine length
// it is). The swatch's own centreline differs from the stem's by the periodic blend: a shear of
// the stem, not a part of the swatch, so the stem's shape is kept as it is here.
Vector3d stem_source(const VineModel& m, const Vector3d& q, double phase) {
  const Vector2d left(-m.axis.y(), m.axis.x());
  const Vector2d p = m.origin + (m.u0 + q.x() + phase) * m.axis + q.y() * left;
  return {p.x(), p.y(), q.z()};
}

// A stem laid along its line: each vertex reached from its cross-section's centre on the line
// by its offset in the frame, along the surface, offsets and heights times the size asked there
// (the tube is made along the pattern coordinate). With `sources`, each vertex's place in the
// swatch too (stem_source). rings: each vertex's cross-section's pattern coordinate.
Placed make_stem(const VineModel& m, const StemFrame& frame, double phase,
                 const Displacement& shell, std::vector<double>* rings, bool sources) {
  std::vector<double> ring;
  const TriMesh t = stem_in_frame(m, frame.pattern_length(), phase, &ring);
  Placed out;
  SurfaceElement& e = out.element;
  e.kind = m.kind;
  e.F = t.F;
  const int nv = static_cast<int>(t.V.rows());
  e.face.resize(static_cast<size_t>(nv));
  e.barycentric.resize(nv, 3);
  e.height.resize(nv);
  out.position.resize(nv, 3);
  double at = -1, size = 1;
  SurfacePoint c;
  Vector3d direction;
  for (int v = 0; v < nv; ++v) {
    const double s = ring[static_cast<size_t>(v)];
    if (s != at) c = frame.at_pattern(s, direction, &size), at = s;
    set_vertex(out, v, frame.offset(c, direction, size * (t.V(v, 0) - s), size * t.V(v, 1)),
               size * t.V(v, 2), shell);
  }
  if (sources) {
    e.source_element.assign(static_cast<size_t>(nv), m.element);
    e.source.resize(nv, 3);
    for (int v = 0; v < nv; ++v)
      e.source.row(v) = stem_source(m, t.V.row(v).transpose(), phase).transpose();
  }
  if (rings) *rings = std::move(ring);
  return out;
}

// A swatch leaf laid rigidly from its attachment at pattern coordinate x, at the size asked
// there: each vertex reached by its offset from there, along the surface. *whole is cleared when
// part of it would lie beyond the base's boundary. `sources`: the swatch's leaf, vertex by vertex
// (SurfaceElement::source).
Placed make_leaf(const VineModel& m, const SwatchLeaf& leaf, const StemFrame& frame, double x,
                 double phase, double push, const Displacement& shell, bool* whole,
                 const MatrixX3d* sources) {
  Placed out;
  SurfaceElement& e = out.element;
  e.kind = leaf.kind;
  e.F = leaf.F;
  e.flat = m.pose(leaf, x, phase);  // a rigid copy of the swatch's leaf
  e.flat.col(0).array() -= x;
  // Moved away from the vine by `push`, on its side of it.
  e.flat.col(1).array() += leaf.P.col(1).mean() < 0 ? -push : push;
  const int nv = static_cast<int>(leaf.P.rows());
  e.face.resize(static_cast<size_t>(nv));
  e.barycentric.resize(nv, 3);
  e.height.resize(nv);
  out.position.resize(nv, 3);
  Vector3d direction;
  double size = 1;
  const SurfacePoint a = frame.at_pattern(x, direction, &size);
  if (size != 1) e.flat *= size;
  for (int v = 0; v < nv; ++v)
    set_vertex(out, v, frame.offset(a, direction, e.flat(v, 0), e.flat(v, 1), whole), e.flat(v, 2),
               shell);
  if (sources) {
    e.source = *sources;
    e.source_element.assign(static_cast<size_t>(e.source.rows()), leaf.element);
  }
  return out;
}

// Whether every vertex of an element lies over one face of the base as given: displaced along
// the normals interpolated over one triangle, a copy of an unfolded element stays unfolded
// (across faces it can fold: where they meet at an angle, or belong to separate pieces).
bool on_one_face(const Refinement& refinement, const SurfaceElement& e) {
  const auto parent = [&](int f) {
    return refinement.parent.empty() ? f : refinement.parent[static_cast<size_t>(f)];
  };
  const int first = parent(e.face.front());
  for (const int f : e.face)
    if (parent(f) != first) return false;
  return true;
}

// Where a leaf is tried, in order: (along the stem, in leaf pitches; away from the vine, in
// tube radii).
constexpr std::array<std::pair<double, double>, 8> kLeafMoves = {
    {{0, 0}, {0.15, 0}, {-0.15, 0}, {0.3, 0}, {-0.3, 0}, {0, 1}, {0.15, 1}, {-0.15, 1}}};
// The farthest a leaf is moved along its stem, in leaf pitches.
constexpr double largest_leaf_shift() {
  double largest = 0;
  for (const auto& [shift, push] : kLeafMoves)
    largest = std::max(largest, shift < 0 ? -shift : shift);
  return largest;
}
constexpr double kLargestLeafShift = largest_leaf_shift();

void check_options(const VineGrowthOptions& o) {
  MQ_CHECK(o.up.allFinite() && o.up.norm() > 0, InvalidInput,
           "vines: the up direction must be finite and non-zero");
  for (const double v : {o.spacing, o.stop_fraction, o.turn_radius})
    MQ_CHECK(std::isfinite(v) && v > 0, InvalidInput,
             "vines: spacing, stop fraction and turn radius must be positive and finite");
  MQ_CHECK(std::isfinite(o.min_length) && o.min_length >= 0, InvalidInput,
           "vines: the shortest stem must be >= 0 and finite");
}

// --- the method's steps ------------------------------------------------------------------------

// The face adjacency TT with no face of the region (#F flags) adjacent to one outside it.
MatrixX3i cut_at_region(const MatrixX3i& TT, const std::vector<char>& region) {
  MQ_CHECK(static_cast<Eigen::Index>(region.size()) == TT.rows(), InternalError,
           "vine growth: a region of ", region.size(), " faces for a base of ", TT.rows());
  MatrixX3i out = TT;
  for (Eigen::Index f = 0; f < TT.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = TT(f, k);
      if (g >= 0 && region[static_cast<size_t>(f)] != region[static_cast<size_t>(g)])
        out(f, k) = -1;
    }
  return out;
}

// The swatch as the vine method uses it: prepared at the detail given, its vine's model, and the
// spacing between stems.
struct VineSwatch {
  PreparedSwatch swatch;
  VineModel model;
  double spacing = 0;  // between stems, for the vine at full detail (the Preview's is the same)
};

// Prepares the swatch and measures its vine. Measured at full detail, so that a Preview grows the
// full run's stems; the model then takes the given swatch's leaves and tube resolution.
VineSwatch analyse_vine_swatch(const SurfaceJob& job, StageTimes& times) {
  ScopedStageTimer timer(times, Stage::Prepare);
  VineSwatch out;
  out.swatch = prepare_swatch(job.swatch);
  PreparedSwatch full;
  const PreparedSwatch& deciding = swatch_at_full_detail(job, out.swatch, full);
  MQ_CHECK(is_vine_swatch(deciding), InvalidInput,
           "the vine method needs a swatch of one long element (a vine) with compact elements "
           "attached along it");
  const int vine = find_vine(deciding, nullptr);
  out.model = analyse_vine(deciding, vine);
  out.spacing = parallel_spacing(out.model);
  if (!job.full_swatch.empty()) out.model = analyse_vine(deciding, vine, &out.swatch);
  return out;
}

// The field the stems follow: the given one at full strength, else `up` projected onto each
// face at the length of its projection (0 where it is normal to the surface: lines run on
// straight there). The smooth default field gives seeds there a direction. *up: the direction
// the seeds are ordered along (the given field's area-weighted mean, when there is one).
MatrixX3d stem_guide_field(const SurfaceJob& job, const SurfaceQuiltingOptions& options,
                           const VineGrowthOptions& vo, const MatrixX3d& FN, Vector3d* up) {
  const TriMesh& base = job.base;
  const int nf = base.num_faces();
  MatrixX3d guide(nf, 3);
  *up = vo.up.normalized();
  if (options.field.rows() > 0) {
    guide = job.field;
    Vector3d mean = Vector3d::Zero();
    const Eigen::VectorXd area = face_areas(base.V, base.F);
    for (int f = 0; f < nf; ++f) mean += area(f) * job.field.row(f).transpose();
    if (mean.norm() > 0) *up = mean.normalized();  // only orders the seeds
  } else {
    for (int f = 0; f < nf; ++f) {
      const Vector3d n = FN.row(f).transpose();
      guide.row(f) = (vo.up.normalized() - vo.up.normalized().dot(n) * n).transpose();
    }
  }
  return guide;
}

// The streamlines' spacing, stopping distances and step from the growth options in swatch vine
// lengths and the stems' spacing (Jobard and Lefer's d_sep and d_test).
StreamlineOptions stem_streamline_options(const VineGrowthOptions& vo, const VineModel& model,
                                          double spacing, const Vector3d& up) {
  StreamlineOptions so;
  so.separation = vo.spacing * spacing;
  so.stop = std::max(vo.stop_fraction * so.separation, 2 * model.extent + model.radius);
  // Lower than Jobard and Lefer's d_sep: distances are taken straight through space, which is
  // shorter than along the surface around a box's edge, where seeds at the spacing beside a
  // line were refused (ivy wall: 0.9 left the edges 54% covered, 0.75 67%).
  so.seed_clearance = std::max(0.75 * so.separation, so.stop);
  so.step = std::min(so.separation / 8, model.period / 8);
  so.self_gap = std::max(2 * so.separation, M_PI * vo.turn_radius * model.period);
  so.obstacle = model.extent + model.radius;
  so.turn_radius = vo.turn_radius * model.period;
  so.min_length = vo.min_length * model.period;
  so.up = up;
  return so;
}

// The size before any work: stems at the spacing over the base's area, as many leaves as the
// swatch's ratio gives; refused over options.max_faces. Evenly spaced streamlines end where they
// come within stop_fraction of another and leave gaps the seeds cannot fill, so their length is
// less than area / spacing: 0.78 of it on David's head, 0.83 on the ivy wall, 0.88 on Spot
// (sample ivy, 2026-12-04); at 0.83 the estimate is within 6% of the faces written on the three
// (issue 28: 20% over). Under a size map a face's area counts over its size squared (stems
// closer, rings and leaves closer along them).
void estimate_vine_faces(const SurfaceJob& job, const VineModel& model, double separation,
                         const SurfaceQuiltingOptions& options, SurfaceQuiltingStats& stats) {
  constexpr double kStreamlineFill = 0.83;
  double area = surface_area(job.base.V, job.base.F);
  if (job.log_size.size()) {
    const Eigen::VectorXd A = face_areas(job.base.V, job.base.F);
    area = 0;
    for (int f = 0; f < job.base.num_faces(); ++f)
      area += A(f) / (nominal_size(job, f) * nominal_size(job, f));
  }
  const double length = kStreamlineFill * area / separation;
  double leaf_faces = 0;
  for (const SwatchLeaf& l : model.leaves) leaf_faces += static_cast<double>(l.F.rows());
  const double faces =
      length * (2.0 * model.segments / model.ring_spacing + leaf_faces / model.period);
  stats.estimated_faces = faces;  // the memory estimate's (--stats `memory`), not the patches'
  MQ_CHECK(faces <= options.max_faces, InvalidInput, "at ", size_option(options),
           " the vines would have about ", faces, " faces, more than the limit of ",
           options.max_faces, " (--max-faces); use a larger ",
           options.element_size > 0 ? "--element-size" : "--scale");
}

// A stem's streamline and where the swatch's pattern starts along it (arc length).
struct StemLine {
  std::vector<Sample> line;
  double phase = 0;
};

// The stems' lines over the base: evenly spaced streamlines (Streamlines above) of the guide
// field, seeded from the lowest face along so.up first so that the stems grow from the bottom,
// and kept off the base's boundary. *short_lines: those traced but too short to grow.
std::vector<StemLine> trace_stems(const SurfaceJob& job, const SurfaceWalker& walker,
                                  const SizeField& size, const std::vector<char>& region,
                                  const MatrixX3d& guide, const StreamlineOptions& so,
                                  int* short_lines, ProgressSink* progress) {
  const TriMesh& base = job.base;
  const int nf = base.num_faces();
  const auto inside = [&](int f) { return region.empty() || region[static_cast<size_t>(f)]; };
  // The base's boundary, and the region's, sampled, keep the tubes off them.
  std::vector<Vector3d> obstacles;
  for (int e = 0; e < job.topo.num_edges(); ++e) {
    const int* faces = job.topo.edge_faces.begin(e);
    if (job.topo.edge_faces.degree(e) == 2 && inside(faces[0]) == inside(faces[1])) continue;
    const Vector3d a = base.V.row(job.topo.E(e, 0)), b = base.V.row(job.topo.E(e, 1));
    const double gap = 0.5 * so.obstacle * size.at_edge(job.topo.E(e, 0), job.topo.E(e, 1));
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / gap)));
    for (int k = 0; k <= n; ++k) obstacles.push_back(a + (b - a) * (static_cast<double>(k) / n));
  }
  // Seeds lowest first (ties by face index: deterministic).
  std::vector<std::pair<double, int>> order(static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f) order[static_cast<size_t>(f)] = {walker.centroid(f).dot(so.up), f};
  std::sort(order.begin(), order.end());
  std::vector<int> seeds;
  for (const auto& [height, f] : order)
    if (inside(f)) seeds.push_back(f);
  Streamlines grower(walker, size, guide, job.field, obstacles, so);
  grower.grow(seeds, progress);
  std::vector<StemLine> stems;
  for (auto& [line, phase] : grower.lines()) stems.push_back({std::move(line), phase});
  *short_lines = grower.short_lines();
  return stems;
}

// A stem made along its line, and its faces that may not stay (bad: #F flags): those that
// intersect the stem itself or dip under the base; `rings`: the arc length of each vertex's
// cross-section, to cut it by.
struct CheckedStem {
  Placed placed;
  std::vector<double> rings;
  std::vector<char> bad;
};

// The stems and leaves laid over the base, each clear of everything placed before it (beyond the
// paper, whose local patches (section 3.1) never join their vines: see the header), and the
// quilt they make.
class VinePlacement {
 public:
  // sources (optional): the prepared swatch, whose points each element's vertices come from are
  // kept (SurfaceElement::source).
  VinePlacement(const SurfaceJob& job, const SurfaceWalker& walker, const VineModel& model,
                const StreamlineOptions& so, double shell_height, const PreparedSwatch* sources)
      : job_(job),
        sources_(sources),
        walker_(walker),
        model_(model),
        so_(so),
        shell_(job.base, shell_height),
        placed_(std::max(0.25 * model.reach, 4 * model.radius)),
        base_height_(job.cleaned.V, job.cleaned.F),
        lowest_(-PlacementCheckOptions().tolerance * shell_height) {}

  // Stems first, in order, then their leaves: nothing placed may intersect what is there. A
  // stem that would intersect itself (bent over a fold of the surface too tight for its tube)
  // or an earlier stem is cut there, and what is left on either side grown in a later round;
  // after the last round such a stem is left out.
  void grow_stems(std::vector<StemLine> pending, VineGrowthStats& vs) {
    const int kRounds = 3;
    for (int round = 0; round < kRounds && !pending.empty(); ++round) {
      const int n = static_cast<int>(pending.size());
      std::vector<CheckedStem> made(static_cast<size_t>(n));
      tbb::parallel_for(0, n, [&](int l) {
        made[static_cast<size_t>(l)] = make_checked_stem(pending[static_cast<size_t>(l)]);
      });
      std::vector<StemLine> next;
      for (int l = 0; l < n; ++l) {
        CheckedStem& c = made[static_cast<size_t>(l)];
        placed_.mark_intersecting(c.placed.position, c.placed.element.F, c.bad);
        if (std::find(c.bad.begin(), c.bad.end(), 1) == c.bad.end()) {
          add(c.placed);
          kept_.push_back(std::move(pending[static_cast<size_t>(l)]));
          continue;
        }
        ++vs.stems_cut;
        split_stem(pending[static_cast<size_t>(l)], c, next);
      }
      pending = std::move(next);
    }
    vs.stems_dropped = static_cast<int>(pending.size());
  }

  // The swatch's leaves along each kept stem at the places its vine carries them. A leaf that
  // dips under the base is tried elsewhere along the stem, like one that meets a neighbour; so
  // is one whose place lies just past an end of the stem (within the largest move), else every
  // stem would end on a bare stretch of up to a pitch (the ivy wall's foot and top were 65%
  // covered, its middle 82%).
  void place_leaves(VineGrowthStats& vs, ProgressSink* progress) {
    const double pitch = model_.period / std::max<size_t>(1, model_.leaves.size());
    for (size_t k = 0; k < kept_.size(); ++k) {
      const StemFrame frame(walker_, kept_[k].line, sized());
      for (const auto& [x, i] :
           leaf_slots(model_, frame.pattern_length(), kept_[k].phase, kLargestLeafShift * pitch)) {
        ++vs.leaf_slots;
        place_leaf(model_.leaves[static_cast<size_t>(i)], frame, x, kept_[k].phase, pitch, vs);
      }
      report_progress(progress, Stage::Leaves, static_cast<double>(k + 1),
                      static_cast<double>(kept_.size()));
    }
  }

  const std::vector<StemLine>& kept() const { return kept_; }
  SurfaceQuilt& quilt() { return quilt_; }

 private:
  bool sized() const { return job_.log_size.size() > 0; }

  // Where a stem or a leaf dips under the base as given (into a pillar beside a wall, where
  // boxes meet), the embedding's check (core/shell/placement_check) would remove it whole: the
  // ivy wall lost 11 stems and 247 leaves so. Stems are cut there, leaves moved.
  bool under_base(const Vector3d& p) const { return base_height_(p) < lowest_; }

  // The stem along st, its faces that intersect one another or dip under the base marked bad
  // (placed stems are checked later, in order).
  CheckedStem make_checked_stem(const StemLine& st) const {
    CheckedStem out;
    const StemFrame frame(walker_, st.line, sized());
    out.placed = make_stem(model_, frame, st.phase, shell_, &out.rings, sources_ != nullptr);
    const Placed& p = out.placed;
    std::vector<char>& b = out.bad;
    b.assign(static_cast<size_t>(p.element.F.rows()), 0);
    IntersectionOptions all;
    all.between_components_only = false;
    for (const auto& [f, g] : intersecting_face_pairs(p.position, p.element.F, all))
      b[static_cast<size_t>(f)] = b[static_cast<size_t>(g)] = 1;
    std::vector<char> under(static_cast<size_t>(p.position.rows()), 0);
    for (Eigen::Index v = 0; v < p.position.rows(); ++v)
      under[static_cast<size_t>(v)] = under_base(p.position.row(v).transpose());
    for (Eigen::Index f = 0; f < p.element.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) b[static_cast<size_t>(f)] |= under[p.element.F(f, k)];
    return out;
  }

  // The pieces of st left once the stretches its bad faces span, widened by the spacing, are
  // cut out: those at least so.min_length long go to `next`, in order along it (in pattern
  // coordinates: c.rings are).
  void split_stem(const StemLine& st, const CheckedStem& c, std::vector<StemLine>& next) const {
    const Placed& p = c.placed;
    std::vector<std::pair<double, double>> cut;
    for (Eigen::Index f = 0; f < p.element.F.rows(); ++f) {
      if (!c.bad[static_cast<size_t>(f)]) continue;
      double lo = kInf, hi = -kInf;
      for (int k = 0; k < 3; ++k) {
        lo = std::min(lo, c.rings[static_cast<size_t>(p.element.F(f, k))]);
        hi = std::max(hi, c.rings[static_cast<size_t>(p.element.F(f, k))]);
      }
      cut.emplace_back(lo - 0.5 * so_.separation, hi + 0.5 * so_.separation);
    }
    std::sort(cut.begin(), cut.end());
    double from = 0;
    const auto piece = [&](double a, double b) {
      if (b - a < so_.min_length) return;
      StemLine part;
      for (const Sample& q : st.line)
        if (q.t >= a && q.t <= b) part.line.push_back(q);
      if (part.line.size() < 2) return;
      const double s0 = part.line.front().s, t0 = part.line.front().t;
      for (Sample& q : part.line) q.s -= s0, q.t -= t0;
      part.phase = st.phase + t0;
      next.push_back(std::move(part));
    };
    for (const auto& [a, b2] : cut) {
      piece(from, a);
      from = std::max(from, b2);
    }
    piece(from, st.line.back().t);
  }

  // One leaf at arc length x of its stem: tried at its place, then a little along the stem
  // either way, then as far again from the vine's axis as the tube's radius (where the surface
  // curves, a leaf laid rigidly from the stem can meet the stem itself); left out when no place
  // is clear.
  void place_leaf(const SwatchLeaf& leaf, const StemFrame& frame, double x, double phase,
                  double pitch, VineGrowthStats& vs) {
    const double S = frame.pattern_length();
    for (const auto& [shift, push] : kLeafMoves) {
      const double xs = x + shift * pitch;
      if (xs < 0 || xs > S) continue;
      bool whole = true;
      Placed p =
          make_leaf(model_, leaf, frame, xs, phase, push * model_.radius, shell_, &whole,
                    sources_ ? &sources_->elements[static_cast<size_t>(leaf.element)].V : nullptr);
      // Whole on the base, clear of everything placed, and not folded through itself
      // (bent over a box's edge, the displacement can fold a leaf).
      if (!whole || placed_.intersects(p.position, p.element.F) >= 0 ||
          (!on_one_face(job_.refinement, p.element) && self_intersects(p.position, p.element.F)) ||
          dips_under_base(p.position))
        continue;
      add(p);
      ++vs.leaves;
      vs.leaves_shifted += shift != 0 || push != 0 ? 1 : 0;
      break;
    }
  }

  bool dips_under_base(const MatrixX3d& P) const {
    for (Eigen::Index v = 0; v < P.rows(); ++v)
      if (under_base(P.row(v).transpose())) return true;
    return false;
  }

  // An element into the quilt and its triangles into the grid of those placed.
  void add(Placed& p) {
    placed_.insert(p.position, p.element.F, static_cast<int>(quilt_.elements.size()));
    quilt_.elements.push_back(std::move(p.element));
  }

  const SurfaceJob& job_;
  const PreparedSwatch* sources_;
  const SurfaceWalker& walker_;
  const VineModel& model_;
  const StreamlineOptions& so_;
  const Displacement shell_;
  TriangleGrid placed_;
  const SignedHeight base_height_;
  const double lowest_;
  SurfaceQuilt quilt_;
  std::vector<StemLine> kept_;
};

// The stems' figures, and the quilt's base, kinds and counts, from the placement.
SurfaceQuilt finish_vine_quilt(SurfaceJob& job, const VineSwatch& vine, VinePlacement& placement,
                               SurfaceQuiltingStats& stats, VineGrowthStats& vs) {
  const std::vector<StemLine>& kept = placement.kept();
  vs.stems = static_cast<int>(kept.size());
  std::vector<double> lengths;
  lengths.reserve(kept.size());
  for (const StemLine& st : kept) {
    lengths.push_back(st.line.back().t);
    vs.total_length += st.line.back().s;
  }
  for (const double l : lengths) vs.total_vines += l;
  vs.total_vines /= vine.model.period;
  if (!lengths.empty()) {
    std::vector<double> sorted = lengths;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    vs.median_length = sorted[sorted.size() / 2] / vine.model.period;
  }
  SurfaceQuilt quilt = std::move(placement.quilt());
  quilt.kinds = vine.swatch.kinds;
  const VineModel& m = vine.model;
  quilt.repeat.element = m.element;
  quilt.repeat.axis = Vector3d(m.axis.x(), m.axis.y(), 0);
  quilt.repeat.start = Vector3d(m.origin.x(), m.origin.y(), 0) + m.u0 * quilt.repeat.axis;
  quilt.repeat.period = m.period;
  quilt.shell_height = vine.swatch.size.z();
  quilt.base = std::move(job.base);
  take_input_bases(job, quilt);
  stats.iterations = vs.stems;
  stats.counts.added = static_cast<int>(quilt.elements.size());
  stats.elements = static_cast<int>(quilt.elements.size());
  for (const SurfaceElement& e : quilt.elements) {
    stats.faces += static_cast<int>(e.F.rows());
    stats.vertices += static_cast<int>(e.face.size());
  }
  return quilt;
}

}  // namespace

bool is_vine_swatch(const PreparedSwatch& swatch) {
  if (swatch.elements.size() < 2) return false;
  std::vector<ElementLength> lengths;
  const int vine = find_vine(swatch, &lengths);
  if (vine < 0) return false;
  if (lengths[static_cast<size_t>(vine)].length < 0.5 * swatch.size.head<2>().maxCoeff())
    return false;
  const Element& v = swatch.elements[static_cast<size_t>(vine)];
  const ClosestPointQuery query(v.V, v.F);
  for (size_t i = 0; i < swatch.elements.size(); ++i) {
    if (static_cast<int>(i) == vine) continue;
    const Element& e = swatch.elements[i];
    const double within = 0.25 * e.footprint_diameter();
    bool attached = false;
    for (Eigen::Index k = 0; k < e.V.rows() && !attached; ++k)
      attached = query.closest(Vector3d(e.V.row(k).transpose()), within).face >= 0;
    if (!attached) return false;
  }
  return true;
}

SurfaceQuilt quilt_surface_vines(const TriMesh& base, const TriMesh& swatch,
                                 const SurfaceQuiltingOptions& options,
                                 const VineGrowthOptions& vine_options,
                                 SurfaceQuiltingStats* stats_out, VineGrowthStats* vine_stats,
                                 ProgressSink* progress) {
  check_options(vine_options);
  SurfaceQuiltingStats stats;
  SurfaceJob job = prepare_surface_job(base, swatch, options, stats);
  return quilt_prepared_vines(std::move(job), std::move(stats), options, vine_options, stats_out,
                              vine_stats, progress);
}

SurfaceQuilt quilt_prepared_vines(SurfaceJob job, SurfaceQuiltingStats stats,
                                  const SurfaceQuiltingOptions& options,
                                  const VineGrowthOptions& vo, SurfaceQuiltingStats* stats_out,
                                  VineGrowthStats* vine_stats, ProgressSink* progress) {
  check_options(vo);
  StageTimes& times = stats.times;
  VineGrowthStats vs;
  const VineSwatch vine = analyse_vine_swatch(job, times);
  const double H = vine.swatch.size.z();
  stats.shell_height = H;
  // Under a region (a mask), its border is a boundary: stems stop there, leaves are laid within.
  const std::vector<char> region = options.region ? options.region(job.base) : std::vector<char>{};
  const MatrixX3i TT = region.empty() ? job.TT : cut_at_region(job.TT, region);
  const SurfaceWalker walker(job.base, TT);
  Vector3d up;
  const MatrixX3d guide = stem_guide_field(job, options, vo, walker.normals(), &up);
  const StreamlineOptions so = stem_streamline_options(vo, vine.model, vine.spacing, up);
  vs.vine_length = vine.model.period;
  vs.spacing = so.separation;
  estimate_vine_faces(job, vine.model, so.separation, options, stats);
  if (options.global.count_only) {
    if (stats_out) *stats_out = std::move(stats);
    if (vine_stats) *vine_stats = vs;
    return {};
  }

  // The header's steps: 1. the stems' lines, 2. their tubes, 3. the leaves along them.
  std::vector<StemLine> stems;
  {
    ScopedStageTimer timer(times, Stage::Streamlines);
    stems = trace_stems(job, walker, SizeField(job), region, guide, so, &vs.streamlines_short,
                        progress);
  }
  VinePlacement placement(job, walker, vine.model, so, H,
                          options.keep_sources ? &vine.swatch : nullptr);
  {
    ScopedStageTimer timer(times, Stage::Stems);
    placement.grow_stems(std::move(stems), vs);
  }
  {
    ScopedStageTimer timer(times, Stage::Leaves);
    placement.place_leaves(vs, progress);
  }
  SurfaceQuilt quilt = finish_vine_quilt(job, vine, placement, stats, vs);
  report_progress(progress, Stage::Leaves, 1, 1);
  if (stats_out) *stats_out = std::move(stats);
  if (vine_stats) *vine_stats = vs;
  return quilt;
}

}  // namespace mq
