#include "core/structure/texture_structure.h"

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <queue>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/segment_distance.h"
#include "core/planar/quilt_elements.h"

namespace mq {

namespace {

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return 0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m), v.end());
  return v[m];
}

// Uniform hash grid over points or boxes, keyed by integer cell coordinates.
class HashGrid3 {
 public:
  explicit HashGrid3(double cell) : cell_(cell > 0 ? cell : 1) {}
  void insert_box(int id, const Vector3d& lo, const Vector3d& hi) {
    const auto a = cell_of(lo), b = cell_of(hi);
    for (long long x = a[0]; x <= b[0]; ++x)
      for (long long y = a[1]; y <= b[1]; ++y)
        for (long long z = a[2]; z <= b[2]; ++z) cells_[key(x, y, z)].push_back(id);
  }
  // Ids in the cells meeting [lo, hi], sorted and unique.
  std::vector<int> query_box(const Vector3d& lo, const Vector3d& hi) const {
    std::vector<int> out;
    const auto a = cell_of(lo), b = cell_of(hi);
    for (long long x = a[0]; x <= b[0]; ++x)
      for (long long y = a[1]; y <= b[1]; ++y)
        for (long long z = a[2]; z <= b[2]; ++z) {
          auto it = cells_.find(key(x, y, z));
          if (it != cells_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
        }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

 private:
  std::array<long long, 3> cell_of(const Vector3d& p) const {
    return {static_cast<long long>(std::floor(p.x() / cell_)),
            static_cast<long long>(std::floor(p.y() / cell_)),
            static_cast<long long>(std::floor(p.z() / cell_))};
  }
  static unsigned long long key(long long x, long long y, long long z) {
    return static_cast<unsigned long long>(x) * 73856093ULL ^
           static_cast<unsigned long long>(y) * 19349663ULL ^
           static_cast<unsigned long long>(z) * 83492791ULL;
  }
  double cell_;
  std::unordered_map<unsigned long long, std::vector<int>> cells_;
};

// Vertex graph distances from `source` over the element's edges (Dijkstra).
std::vector<double> graph_distances(const MatrixX3d& V, const Adjacency& adj, int source) {
  std::vector<double> dist(V.rows(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
  dist[source] = 0;
  heap.emplace(0.0, source);
  while (!heap.empty()) {
    const auto [d, v] = heap.top();
    heap.pop();
    if (d > dist[v]) continue;
    for (const int* w = adj.begin(v); w != adj.end(v); ++w) {
      const double nd = d + (V.row(*w) - V.row(v)).norm();
      if (nd < dist[*w]) {
        dist[*w] = nd;
        heap.emplace(nd, *w);
      }
    }
  }
  return dist;
}

int farthest(const std::vector<double>& dist) {
  int best = 0;
  for (size_t v = 0; v < dist.size(); ++v)
    if (std::isfinite(dist[v]) && dist[v] > dist[best]) best = static_cast<int>(v);
  return best;
}

// Per-element figures that need only the element itself (and the swatch, for its shape).
// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 sees the implicit copy's __i0
struct ElementFigures {
  ElementStructure s;
  std::optional<Loop> loop;
  bool closed_genus_one = false;  // every edge in two faces, Euler characteristic 0
  Vector3d end[2] = {Vector3d::Zero(), Vector3d::Zero()};
  double raw_size = 0, raw_stretch = 0;  // shape figures before division by the linear scale
};

// Principal extents (standard deviations along the principal axes, descending) and the axes.
void principal_extents(const MatrixX3d& V, Vector3d& extents, Eigen::Matrix3d* axes = nullptr) {
  const Vector3d mean = V.colwise().mean().transpose();
  const MatrixX3d D = V.rowwise() - mean.transpose();
  const Eigen::Matrix3d cov =
      D.transpose() * D / static_cast<double>(std::max<Eigen::Index>(1, V.rows()));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  for (int k = 0; k < 3; ++k) extents(k) = std::sqrt(std::max(0.0, eig.eigenvalues()(2 - k)));
  if (axes)
    for (int k = 0; k < 3; ++k) axes->col(k) = eig.eigenvectors().col(2 - k);
}

// Squared residual left by the best similarity (rotation, uniform scale, translation) taking the
// centred shape X onto the centred points Y, over |Y|^2 (Umeyama; reflections excluded).
double similarity_residual(const MatrixX3d& X, const MatrixX3d& Y) {
  const double xx = X.squaredNorm(), yy = Y.squaredNorm();
  if (!(xx > 0) || !(yy > 0)) return std::numeric_limits<double>::infinity();
  // The singular values of H = X^T Y, the smallest negated when H reverses orientation (the
  // best rotation then leaves that axis flipped).
  const Eigen::Matrix3d H = X.transpose() * Y;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H.transpose() * H,
                                                           Eigen::EigenvaluesOnly);
  Vector3d sv;
  for (int k = 0; k < 3; ++k) sv(k) = std::sqrt(std::max(0.0, eig.eigenvalues()(k)));
  if (H.determinant() < 0) sv(0) = -sv(0);
  const double t = sv.sum();
  return std::max(0.0, yy - t * t / xx) / yy;
}

// The shape figures of an element (vertices V, #V by 3) against its swatch kind, unscaled:
// size and stretch in output per swatch length (ElementStructure documents them).
void shape_against(const MatrixX3d& V, const SwatchKind& kind, ElementFigures& out) {
  ElementStructure& e = out.s;
  const Vector3d mean = V.colwise().mean().transpose();
  const MatrixX3d Y = V.rowwise() - mean.transpose();
  const SwatchKind::Shape* source = nullptr;
  double best = std::numeric_limits<double>::infinity();
  for (const SwatchKind::Shape& shape : kind.shapes) {
    if (shape.V.rows() != V.rows()) continue;
    const double r = similarity_residual(shape.V, Y);
    if (r < best) {
      best = r;
      source = &shape;
    }
  }
  if (source) {
    // The best affine map A (Y ~ X A^T): A = (Y^T X)(X^T X)^-1.
    const MatrixX3d& X = source->V;
    const Eigen::Matrix3d xtx = X.transpose() * X;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(xtx);
    if (eig.eigenvalues()(0) > 1e-12 * eig.eigenvalues()(2)) {
      const Eigen::Matrix3d A = (Y.transpose() * X) * xtx.inverse();
      const double residual = (Y - X * A.transpose()).squaredNorm() / Y.squaredNorm();
      // A copy (however bent) is fitted to a fraction of its spread; vertices in another order
      // leave about all of it.
      if (residual < 0.25) {
        const Eigen::Matrix<double, 3, 2> M = A * source->axes;
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> m(M.transpose() * M);
        const double t1 = std::sqrt(std::max(0.0, m.eigenvalues()(1)));
        const double t2 = std::sqrt(std::max(0.0, m.eigenvalues()(0)));
        if (t2 > 0) {
          out.raw_size = std::sqrt(t1 * t2);
          out.raw_stretch = t1;
          e.aspect = t1 / t2;
          e.by_correspondence = true;
          return;
        }
      }
    }
  }
  Vector3d s;
  principal_extents(V, s);
  const Vector3d& r = kind.extents;
  if (!(s(1) > 0) || !(r(0) > 0) || !(r(1) > 0)) return;
  const double q = (s(0) / s(1)) / (r(0) / r(1));
  out.raw_size = std::sqrt(s(0) * s(1) / (r(0) * r(1)));
  e.aspect = std::max(q, 1 / q);
  out.raw_stretch = out.raw_size * std::sqrt(e.aspect);
}

ElementFigures figures_of(const TriMesh& part, int loop_bins) {
  ElementFigures out;
  const MatrixX3d& V = part.V;
  out.s.vertices = static_cast<int>(V.rows());
  out.s.centre = V.colwise().mean().transpose();
  double r = 0;
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    r = std::max(r, (V.row(v).transpose() - out.s.centre).norm());
  out.s.size = 2 * r;
  out.s.area = surface_area(V, part.F);
  out.loop = ring_centre_loop(V, part.F, loop_bins);
  out.s.ring_shaped = out.s.ring = out.loop.has_value();
  if (out.s.ring) {
    const RingShape shape = ring_shape(V, part.F, *out.loop);
    out.s.wire = shape.wire;
    out.s.opening = shape.opening;
    out.s.fold = shape.fold;
    return out;
  }
  if (V.rows() < 2) return out;
  {
    const EdgeTopology topo = edge_topology(part.F, static_cast<int>(V.rows()));
    bool closed = true;
    for (int e = 0; e < topo.num_edges() && closed; ++e) closed = topo.edge_faces.degree(e) == 2;
    out.closed_genus_one = closed && V.rows() - topo.num_edges() + part.F.rows() == 0;
  }
  // Length: the double-sweep graph diameter (exact on a tube, a close lower bound elsewhere;
  // twice it round a closed tube, whose farthest points are half way round); width: the
  // diameter a tube of that length and the element's area would have.
  const Adjacency adj = vertex_adjacency(part.F, static_cast<int>(V.rows()));
  const int a = farthest(graph_distances(V, adj, 0));
  const std::vector<double> from_a = graph_distances(V, adj, a);
  const int b = farthest(from_a);
  const double length = (out.closed_genus_one ? 2 : 1) * from_a[b];
  if (!(length > 0)) return out;
  const double width = out.s.area / (M_PI * length);
  out.s.length = length;
  out.s.width = width;
  // Long also from end to end: a coarse box's edge path between opposite corners zigzags over
  // its faces (0.7 against 0.44 straight on a 0.3 x 0.3 x 0.1 box), which made a swatch of such
  // studs count as threads; a thread's ends lie apart as far as its length says, unless it
  // bends back on itself.
  out.s.long_element = length >= 4 * width && (V.row(a) - V.row(b)).norm() >= 4 * width;
  out.end[0] = V.row(a).transpose();
  out.end[1] = V.row(b).transpose();
  return out;
}

// Nearest-rank percentile of sorted values (p in (0, 1]).
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0;
  const size_t k = static_cast<size_t>(std::ceil(p * static_cast<double>(sorted.size())));
  return sorted[std::min(sorted.size(), std::max<size_t>(k, 1)) - 1];
}

// The plane of the element centres: origin, in-plane axes u, w and the spread off the plane.
struct CentrePlane {
  Vector3d origin = Vector3d::Zero(), u = Vector3d::UnitX(), w = Vector3d::UnitY();
  double thickness = 0;
  Vector2d lo = Vector2d::Zero(), hi = Vector2d::Zero();  // centres' box in (u, w)
};

CentrePlane centre_plane(const std::vector<Vector3d>& centres) {
  CentrePlane p;
  if (centres.empty()) return p;
  for (const Vector3d& c : centres) p.origin += c;
  p.origin /= static_cast<double>(centres.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vector3d& c : centres) cov += (c - p.origin) * (c - p.origin).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  // In-plane axes: the world axis most nearly in the plane, projected, and its normal in the
  // plane, so a layer in the xy plane gets x and y (PCA axes of a square layer are arbitrary).
  const Vector3d n = eig.eigenvectors().col(0);
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(n(k)) < std::abs(n(axis))) axis = k;
  p.u = (Vector3d::Unit(axis) - n * n(axis)).normalized();
  p.w = n.cross(p.u);
  double nlo = std::numeric_limits<double>::infinity(), nhi = -nlo;
  p.lo = Vector2d::Constant(nlo);
  p.hi = Vector2d::Constant(-nlo);
  for (const Vector3d& c : centres) {
    const Vector3d d = c - p.origin;
    const Vector2d q(d.dot(p.u), d.dot(p.w));
    p.lo = p.lo.cwiseMin(q);
    p.hi = p.hi.cwiseMax(q);
    nlo = std::min(nlo, d.dot(n));
    nhi = std::max(nhi, d.dot(n));
  }
  p.thickness = nhi - nlo;
  return p;
}

// Polygon clipped to the half-plane {x : (x - m) . n <= 0}.
std::vector<Vector2d> clip(const std::vector<Vector2d>& poly, const Vector2d& m,
                           const Vector2d& n) {
  std::vector<Vector2d> out;
  const size_t k = poly.size();
  for (size_t i = 0; i < k; ++i) {
    const Vector2d& a = poly[i];
    const Vector2d& b = poly[(i + 1) % k];
    const double da = (a - m).dot(n), db = (b - m).dot(n);
    if (da <= 0) out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

double polygon_area(const std::vector<Vector2d>& poly) {
  double a = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vector2d& p = poly[i];
    const Vector2d& q = poly[(i + 1) % poly.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * std::abs(a);
}

// Area of the Voronoi cell of `centre` among `others` in the plane through centre normal to n,
// started as the square of half-size radius: 0 when the cell does not close inside it (a
// neighbour is missing on some side).
double voronoi_cell_area(const Vector3d& centre, const std::vector<Vector3d>& others,
                         const Vector3d& n, double radius) {
  const Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  std::vector<Vector2d> cell = {Vector2d(-radius, -radius), Vector2d(radius, -radius),
                                Vector2d(radius, radius), Vector2d(-radius, radius)};
  for (const Vector3d& o : others) {
    const Vector3d d = o - centre;
    const Vector2d q(d.dot(a), d.dot(b));
    if (!(q.squaredNorm() > 0)) continue;
    cell = clip(cell, 0.5 * q, q);
    if (cell.size() < 3) return 0;
  }
  const double inside = radius * (1 - 1e-9);
  for (const Vector2d& p : cell)
    if (std::abs(p.x()) >= inside || std::abs(p.y()) >= inside) return 0;
  return polygon_area(cell);
}

}  // namespace

TextureBorder mesh_border(const MatrixX3d& V, const MatrixX3i& F) {
  TextureBorder b;
  const EdgeTopology topo = edge_topology(F, static_cast<int>(V.rows()));
  for (int e = 0; e < topo.num_edges(); ++e)
    if (topo.is_boundary(e))
      b.segments.emplace_back(V.row(topo.E(e, 0)).transpose(), V.row(topo.E(e, 1)).transpose());
  b.kind = b.segments.empty() ? TextureBorder::Kind::None : TextureBorder::Kind::Segments;
  return b;
}

double StructureReport::share_with_links(int k) const {
  if (interior_rings == 0 || k < 0 || k >= static_cast<int>(interior_link_histogram.size()))
    return 0;
  return static_cast<double>(interior_link_histogram[static_cast<size_t>(k)]) / interior_rings;
}

const char* ring_defect_name(RingDefect defect) {
  switch (defect) {
    case RingDefect::None:
      return "none";
    case RingDefect::NotRing:
      return "not_ring";
    case RingDefect::NoHole:
      return "no_hole";
    case RingDefect::Folded:
      return "folded";
  }
  return "none";
}

int SwatchStructure::ring_kinds() const {
  int n = 0;
  for (const SwatchKind& k : kinds) n += k.ring ? 1 : 0;
  return n;
}

int swatch_kind_for(const SwatchStructure& swatch, const std::string& kind, int vertices, bool ring,
                    const MatrixX3d* positions) {
  const int n = static_cast<int>(swatch.kinds.size());
  for (int k = 0; k < n; ++k)
    if (swatch.kinds[k].name == kind) return k;
  int best = -1;
  double fit = std::numeric_limits<double>::infinity();
  MatrixX3d centred;
  if (positions && positions->rows() == vertices)
    centred = positions->rowwise() - positions->colwise().mean();
  for (int k = 0; k < n; ++k)
    for (const SwatchKind::Shape& shape : swatch.kinds[k].shapes) {
      if (shape.V.rows() != vertices) continue;
      if (centred.rows() == 0) return k;
      const double r = similarity_residual(shape.V, centred);
      if (best < 0 || r < fit) {
        best = k;
        fit = r;
      }
    }
  if (best >= 0) return best;
  for (int k = 0; k < n; ++k) {
    const SwatchKind& c = swatch.kinds[k];
    if (ring && c.ring && (best < 0 || c.rings > swatch.kinds[best].rings)) best = k;
  }
  if (best >= 0) return best;
  for (int k = 0; k < n; ++k)
    if (best < 0 || swatch.kinds[k].elements > swatch.kinds[best].elements) best = k;
  return best;
}

void StructureOptions::validate() const {
  MQ_CHECK(loop_bins >= 8, InvalidInput, "a centre loop needs at least 8 bins, got ", loop_bins);
  MQ_CHECK(std::isfinite(interior_margin) && interior_margin >= 0 && std::isfinite(end_margin) &&
               end_margin >= 0 && std::isfinite(area) && area >= 0 && std::isfinite(linear_scale) &&
               linear_scale >= 0,
           InvalidInput, "structure options: margins, area and scale must be finite and >= 0");
}

namespace {

// The figures of every element (a connected component), in parallel; with a swatch, each is
// matched to its swatch kind (by name, else swatch_kind_for) and a compact one measured
// against it.
std::vector<ElementFigures> measure_elements(const TriMesh& mesh, const StructureOptions& options,
                                             const std::vector<std::string>& kinds) {
  std::vector<int> fc;
  const int n = connected_components(mesh.F, mesh.num_vertices(), fc);
  const std::vector<std::vector<int>> groups = component_faces(fc, n);
  const std::vector<int> element_kind = component_kinds(mesh, fc, n);
  const SwatchStructure* swatch = options.swatch;
  // The swatch kind of each of the mesh's kinds by name (-1: matched per element).
  std::vector<int> by_name(kinds.size(), -1);
  if (swatch)
    for (size_t k = 0; k < kinds.size(); ++k)
      for (size_t j = 0; j < swatch->kinds.size(); ++j)
        if (swatch->kinds[j].name == kinds[k]) by_name[k] = static_cast<int>(j);

  std::vector<ElementFigures> figures(static_cast<size_t>(n));
  tbb::parallel_for(0, n, [&](int c) {
    const TriMesh part = extract_faces(mesh, groups[c]);
    ElementFigures& f = figures[static_cast<size_t>(c)];
    f = figures_of(part, options.loop_bins);
    f.s.kind = element_kind[static_cast<size_t>(c)];
    if (!swatch || swatch->kinds.empty()) return;
    int sk = by_name[static_cast<size_t>(f.s.kind)];
    if (sk < 0)
      sk = swatch_kind_for(*swatch, kinds[static_cast<size_t>(f.s.kind)], f.s.vertices,
                           f.s.ring_shaped, &part.V);
    f.s.swatch_kind = sk;
    if (sk >= 0 && swatch->kinds[sk].compact) shape_against(part.V, swatch->kinds[sk], f);
  });
  return figures;
}

// What each of the mesh's own kinds is, for a mesh measured without a swatch (with one, the
// swatch kinds decide): a ring kind when most of its elements are ring-shaped, a long kind
// when most are long (and it is no ring kind); and its wire gauge, the median wire of its
// ring-shaped elements, which a ring's free hole must pass (RingDefect::NoHole).
struct KindRoles {
  std::vector<char> ring, long_kind;
  std::vector<double> gauge;
};

KindRoles kind_roles(const std::vector<ElementFigures>& figures, size_t kinds, bool swatch) {
  KindRoles roles;
  roles.ring.assign(kinds, 0);
  roles.long_kind.assign(kinds, 0);
  roles.gauge.assign(kinds, 0);
  std::vector<int> shaped(kinds, 0), longs(kinds, 0), all(kinds, 0);
  std::vector<std::vector<double>> wires(kinds);
  for (const ElementFigures& f : figures) {
    const size_t k = static_cast<size_t>(f.s.kind);
    ++all[k];
    shaped[k] += f.s.ring_shaped ? 1 : 0;
    longs[k] += f.s.long_element ? 1 : 0;
    if (f.s.ring_shaped) wires[k].push_back(f.s.wire);
  }
  for (size_t k = 0; k < kinds; ++k) {
    roles.gauge[k] = median(wires[k]);
    if (swatch) continue;
    roles.ring[k] = 2 * shaped[k] > all[k];
    roles.long_kind[k] = !roles.ring[k] && 2 * longs[k] > all[k];
  }
  return roles;
}

// Decides what an element is from its shape and its kind's role (sk: its swatch kind, or
// nullptr to take the mesh's own roles): a thread closed on itself (as long as its loop, no
// ends), a ring that is not ring-shaped (a torn, merged or melted ring: a miss, not a thread
// with two ends), or a ring-shaped one judged for a hole and a fold (issue 23).
void classify_element(ElementFigures& f, const SwatchKind* sk, const KindRoles& roles,
                      bool judge_folds) {
  ElementStructure& e = f.s;
  const size_t kind = static_cast<size_t>(e.kind);
  const bool of_ring_kind = sk ? sk->ring : roles.ring[kind] != 0;
  const bool of_long_kind = sk ? !sk->ring && !sk->compact : roles.long_kind[kind] != 0;
  if (of_long_kind && !of_ring_kind && (e.ring_shaped || (f.closed_genus_one && e.long_element))) {
    if (e.ring_shaped) {
      double length = 0;
      const Loop& loop = *f.loop;
      for (size_t k = 0; k < loop.size(); ++k)
        length += (loop[(k + 1) % loop.size()] - loop[k]).norm();
      e.length = length;
      e.width = length > 0 ? e.area / (M_PI * length) : 0;
    }
    e.ring = false;
    e.long_element = e.closed = true;
    e.wire = e.opening = e.fold = 0;
  } else if (!e.ring_shaped && of_ring_kind) {
    e.ring = true;
    e.defect = RingDefect::NotRing;
    e.long_element = false;
  } else if (e.ring_shaped) {
    const double reference = sk && sk->ring ? sk->fold : 0.0;
    if (!(e.opening >= std::max(e.wire, roles.gauge[kind])))
      e.defect = RingDefect::NoHole;
    else if (judge_folds && e.fold - reference > kFoldLimit)
      e.defect = RingDefect::Folded;
  }
}

// Classifies every element into report.elements and takes the medians of their sizes, areas
// and long elements' lengths and widths.
void classify_elements(std::vector<ElementFigures>& figures, const StructureOptions& options,
                       StructureReport& report) {
  const SwatchStructure* swatch = options.swatch;
  const KindRoles roles = kind_roles(figures, report.kinds.size(), swatch != nullptr);
  const size_t n = figures.size();
  report.elements.resize(n);
  std::vector<double> sizes(n), areas(n), widths, lengths;
  for (size_t c = 0; c < n; ++c) {
    ElementFigures& f = figures[c];
    const int sk = f.s.swatch_kind;
    classify_element(f, swatch && sk >= 0 ? &swatch->kinds[sk] : nullptr, roles,
                     options.judge_folds);
    const ElementStructure& e = f.s;
    report.elements[c] = e;
    sizes[c] = e.size;
    areas[c] = e.area;
    if (e.long_element) {
      widths.push_back(e.width);
      lengths.push_back(e.length);
    }
  }
  report.median_size = median(sizes);
  report.median_area = median(areas);
  report.median_long_length = median(lengths);
  report.median_long_width = median(widths);
}

// The shape figures at the output's scale: the given one, else from the long elements' widths
// for a swatch mostly of long elements (welded threads' areas follow their lengths), else from
// the median element areas.
void scale_shapes(const std::vector<ElementFigures>& figures, const SwatchStructure& swatch,
                  double given_scale, StructureReport& report) {
  double scale = given_scale;
  const bool long_swatch =
      2 * swatch.report.long_elements > static_cast<int>(swatch.report.elements.size());
  if (!(scale > 0) && long_swatch && report.median_long_width > 0 &&
      swatch.report.median_long_width > 0)
    scale = report.median_long_width / swatch.report.median_long_width;
  if (!(scale > 0) && swatch.report.median_area > 0)
    scale = std::sqrt(report.median_area / swatch.report.median_area);
  report.linear_scale = scale > 0 ? scale : 0;
  for (size_t c = 0; c < figures.size() && scale > 0; ++c) {
    const ElementFigures& f = figures[c];
    ElementStructure& e = report.elements[c];
    if (!(f.raw_size > 0)) continue;
    e.size_ratio = f.raw_size / scale;
    e.stretch = f.raw_stretch / scale;
  }
}

// The median distance from a centre to the nearest other, searched in the 27 cells of a grid
// of the median element size.
double median_spacing(const std::vector<Vector3d>& centres, double median_size) {
  const int n = static_cast<int>(centres.size());
  const double cell = median_size > 0 ? median_size : 1.0;
  HashGrid3 grid(cell);
  for (int c = 0; c < n; ++c) grid.insert_box(c, centres[c], centres[c]);
  std::vector<double> nearest(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  const Vector3d r = Vector3d::Constant(cell);
  tbb::parallel_for(0, n, [&](int c) {
    for (const int d : grid.query_box(centres[c] - r, centres[c] + r))
      if (d != c) nearest[c] = std::min(nearest[c], (centres[d] - centres[c]).norm());
  });
  return median(nearest);
}

// The border options.border gives, or with automatic_border a flat layer's box (centres within
// half an element size of their plane) or none.
TextureBorder texture_border(const StructureOptions& options, const CentrePlane& plane,
                             double median_size) {
  TextureBorder border = options.border;
  if (options.automatic_border)
    border.kind = plane.thickness <= 0.5 * median_size ? TextureBorder::Kind::FlatBox
                                                       : TextureBorder::Kind::None;
  return border;
}

// Distance from a point to the border (infinite without one).
double border_distance(const TextureBorder& border, const CentrePlane& plane, const Vector3d& p) {
  switch (border.kind) {
    case TextureBorder::Kind::None:
      return std::numeric_limits<double>::infinity();
    case TextureBorder::Kind::FlatBox: {
      const Vector3d d = p - plane.origin;
      const Vector2d q(d.dot(plane.u), d.dot(plane.w));
      const double m = std::min(
          {q.x() - plane.lo.x(), plane.hi.x() - q.x(), q.y() - plane.lo.y(), plane.hi.y() - q.y()});
      return std::max(0.0, m);
    }
    case TextureBorder::Kind::Segments: {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& [a, b] : border.segments)
        best = std::min(best, point_segment_distance(p, a, b));
      return best;
    }
  }
  return std::numeric_limits<double>::infinity();
}

// The distance from the border beyond which an element is interior: given, else one element
// size and one spacing (on a base the outermost elements must lie wholly on it, so their
// centres can be a size and a spacing from its edge). The size of the largest kind (of those
// holding a tenth of the elements): the square sheet's flat rings lose connectors that would
// stand beyond the edge, and its connectors, most of its elements, are smaller.
double interior_margin(const StructureOptions& options, const StructureReport& report) {
  if (options.interior_margin > 0) return options.interior_margin;
  double largest_kind = report.median_size;
  std::vector<std::vector<double>> by_kind(report.kinds.size());
  for (const ElementStructure& e : report.elements)
    by_kind[static_cast<size_t>(e.kind)].push_back(e.size);
  for (const std::vector<double>& k : by_kind)
    if (10 * k.size() >= report.elements.size()) largest_kind = std::max(largest_kind, median(k));
  return largest_kind + report.median_spacing;
}

// Marks the interior elements and counts the long elements' ends away from the border.
void mark_interior(const std::vector<ElementFigures>& figures, const TextureBorder& border,
                   const CentrePlane& plane, double margin, double end_margin,
                   StructureReport& report) {
  const int n = static_cast<int>(report.elements.size());
  tbb::parallel_for(0, n, [&](int c) {
    ElementStructure& e = report.elements[c];
    e.interior = border_distance(border, plane, e.centre) > margin;
    if (e.long_element && !e.closed)
      for (const Vector3d& p : figures[c].end)
        if (border_distance(border, plane, p) > end_margin) ++e.interior_ends;
  });
}

// Interlinked rings: loops whose boxes overlap (b must cross the cone over a, which lies in
// a's convex hull) are tested exactly. A pair counts as a link only when neither ring is
// degenerate; loop_links count every interlinked centre loop.
void link_rings(const std::vector<ElementFigures>& figures, StructureReport& report) {
  const int n = static_cast<int>(figures.size());
  std::vector<int> rings;
  std::vector<Vector3d> lo(static_cast<size_t>(n)), hi(static_cast<size_t>(n));
  std::vector<double> ring_sizes;
  for (int c = 0; c < n; ++c) {
    if (!figures[c].loop || !report.elements[c].ring) continue;
    rings.push_back(c);
    lo[c] = hi[c] = figures[c].loop->front();
    for (const Vector3d& p : *figures[c].loop) {
      lo[c] = lo[c].cwiseMin(p);
      hi[c] = hi[c].cwiseMax(p);
    }
    ring_sizes.push_back(figures[c].s.size);
  }
  HashGrid3 grid(std::max(median(ring_sizes), 1e-12));
  for (const int c : rings) grid.insert_box(c, lo[c], hi[c]);
  std::vector<std::vector<int>> partners(static_cast<size_t>(n));
  tbb::parallel_for(size_t(0), rings.size(), [&](size_t k) {
    const int a = rings[k];
    for (const int b : grid.query_box(lo[a], hi[a])) {
      if (b <= a) continue;
      if ((lo[a].array() > hi[b].array()).any() || (lo[b].array() > hi[a].array()).any()) continue;
      if (linking_number(*figures[a].loop, *figures[b].loop) != 0) partners[a].push_back(b);
    }
  });
  for (const int a : rings)
    for (const int b : partners[a]) {
      ElementStructure &ea = report.elements[a], &eb = report.elements[b];
      ++report.loop_linked_pairs;
      ++ea.loop_links;
      ++eb.loop_links;
      if (ea.degenerate() || eb.degenerate()) continue;
      report.linked_pairs.emplace_back(a, b);
      ++ea.links;
      ++eb.links;
    }
}

// The report's counts: long elements and their ends, compact elements, rings by defect and
// the link histograms (over all rings and over the interior ones).
void count_elements(StructureReport& report) {
  int max_links = 0;
  for (const ElementStructure& e : report.elements)
    if (e.ring) max_links = std::max(max_links, e.links);
  report.link_histogram.assign(static_cast<size_t>(max_links) + 1, 0);
  report.interior_link_histogram.assign(static_cast<size_t>(max_links) + 1, 0);
  for (const ElementStructure& e : report.elements) {
    if (e.long_element) {
      ++report.long_elements;
      report.closed_long_elements += e.closed ? 1 : 0;
      report.ends += e.closed ? 0 : 2;
      report.interior_ends += e.interior_ends;
      report.long_length += e.length;
    } else {
      ++report.compact_elements;
    }
    if (!e.ring) continue;
    const size_t defect = static_cast<size_t>(e.defect);
    ++report.rings;
    ++report.defects[defect];
    if (e.links == 0) ++report.isolated_rings;
    if (!e.degenerate()) ++report.link_histogram[e.links];
    if (e.interior) {
      ++report.interior_rings;
      ++report.interior_defects[defect];
      if (!e.degenerate()) ++report.interior_link_histogram[e.links];
    }
  }
}

// The tangent-plane normal at centres[c] among its neighbours `others`: the surface's when
// given, else the normal of the plane best fitting them all.
Vector3d tangent_normal(const std::vector<Vector3d>& centres, int c,
                        const std::vector<Vector3d>& others, const Vector3d& own, bool given) {
  if (given) return own;
  Vector3d mean = centres[c];
  for (const Vector3d& o : others) mean += o;
  mean /= static_cast<double>(others.size() + 1);
  Eigen::Matrix3d cov = (centres[c] - mean) * (centres[c] - mean).transpose();
  for (const Vector3d& o : others) cov += (o - mean) * (o - mean).transpose();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
}

// Density from the Voronoi cells of interior elements in their tangent planes (neighbours
// within 4 spacings; with surface normals, those whose surface faces another way are none).
void measure_density(const std::vector<Vector3d>& centres,
                     const std::function<Vector3d(const Vector3d&)>& surface_normal,
                     StructureReport& report) {
  const int n = static_cast<int>(centres.size());
  const double radius =
      4 * (report.median_spacing > 0 ? report.median_spacing : report.median_size);
  HashGrid3 grid(radius > 0 ? radius : 1.0);
  for (int c = 0; c < n; ++c) grid.insert_box(c, centres[c], centres[c]);
  std::vector<double> cell_area(static_cast<size_t>(n), 0);
  tbb::parallel_for(0, n, [&](int c) {
    if (!report.elements[c].interior || !(radius > 0)) return;
    const Vector3d r = Vector3d::Constant(radius);
    std::vector<Vector3d> others;
    const Vector3d own = surface_normal ? surface_normal(centres[c]) : Vector3d::Zero();
    for (const int d : grid.query_box(centres[c] - r, centres[c] + r)) {
      if (d == c || (centres[d] - centres[c]).norm() > radius) continue;
      if (surface_normal && surface_normal(centres[d]).dot(own) < 0.5) continue;
      others.push_back(centres[d]);
    }
    if (others.size() < 3) return;
    const Vector3d normal = tangent_normal(centres, c, others, own, bool(surface_normal));
    if (!(normal.norm() > 0) || !normal.allFinite()) return;
    cell_area[c] = voronoi_cell_area(centres[c], others, normal.normalized(), radius);
  });
  double total = 0;
  for (int c = 0; c < n; ++c)
    if (cell_area[c] > 0) {
      total += cell_area[c];
      ++report.density_cells;
    }
  report.density = total > 0 ? report.density_cells / total : 0;
}

// The textured area: given, or for a flat layer the centres' box grown by one spacing (a
// lattice of a x b cells then has exactly its area); and the interior ends per unit of the
// area farther than end_margin from the border.
void measure_area(double given_area, const TextureBorder& border, const CentrePlane& plane,
                  double end_margin, StructureReport& report) {
  double area = given_area, end_area = given_area;
  if (!(area > 0) && border.kind == TextureBorder::Kind::FlatBox) {
    const Vector2d ext = plane.hi - plane.lo;
    const double d = report.median_spacing;
    area = (ext.x() + d) * (ext.y() + d);
  }
  if (!(area > 0)) return;
  end_area = area;
  if (border.kind == TextureBorder::Kind::FlatBox) {
    const Vector2d ext = plane.hi - plane.lo;
    end_area = std::max(0.0, ext.x() - 2 * end_margin) * std::max(0.0, ext.y() - 2 * end_margin);
  } else if (border.kind == TextureBorder::Kind::Segments) {
    double perimeter = 0;
    for (const auto& [a, b] : border.segments) perimeter += (b - a).norm();
    end_area = std::max(0.0, area - perimeter * end_margin);
  }
  report.area = area;
  report.interior_ends_per_area = end_area > 0 ? report.interior_ends / end_area : 0;
}

}  // namespace

StructureReport measure_structure(const TriMesh& mesh, const StructureOptions& options) {
  MQ_CHECK(mesh.V.allFinite(), InvalidInput, "the mesh has non-finite vertex coordinates");
  check_kinds(mesh);
  options.validate();
  StructureReport report;
  report.kinds = has_kinds(mesh) ? mesh.kinds : std::vector<std::string>{kDefaultKind};
  std::vector<ElementFigures> figures = measure_elements(mesh, options, report.kinds);
  classify_elements(figures, options, report);
  if (figures.empty()) return report;
  if (options.swatch) scale_shapes(figures, *options.swatch, options.linear_scale, report);

  std::vector<Vector3d> centres;
  for (const ElementStructure& e : report.elements) centres.push_back(e.centre);
  report.median_spacing = median_spacing(centres, report.median_size);
  const CentrePlane plane = centre_plane(centres);
  const TextureBorder border = texture_border(options, plane, report.median_size);
  report.border = border.kind;
  // Ends this close to the border are where the texture stops, not breaks.
  const double end_margin =
      options.end_margin > 0 ? options.end_margin : 5 * report.median_long_width;
  mark_interior(figures, border, plane, interior_margin(options, report), end_margin, report);
  link_rings(figures, report);
  count_elements(report);
  measure_density(centres, options.surface_normal, report);
  measure_area(options.area, border, plane, end_margin, report);
  return report;
}

namespace {

// The largest link count held by at least a tenth of `rings` rings (-1 when none is).
int common_count(const std::vector<int>& histogram, int rings) {
  if (rings <= 0) return -1;
  const int need = std::max(1, static_cast<int>(std::ceil(0.1 * rings)));
  for (int k = static_cast<int>(histogram.size()) - 1; k >= 0; --k)
    if (histogram[k] >= need) return k;
  return -1;
}

}  // namespace

namespace {

// One more of `value` in a histogram of counts, grown as needed.
void count_in(std::vector<int>& histogram, int value) {
  if (histogram.size() <= static_cast<size_t>(value))
    histogram.resize(static_cast<size_t>(value) + 1, 0);
  ++histogram[static_cast<size_t>(value)];
}

// What a swatch kind's elements gather before their medians: the link counts of its rings
// that are not degenerate, their folds and the elements' principal extents.
struct KindSamples {
  std::vector<int> histogram;
  std::vector<double> folds;
  std::array<std::vector<double>, 3> extents;
};

// Adds one swatch element (its figures e and its mesh part) to its kind: counts, samples and,
// unless a similarity takes one of the kind's shapes of as many vertices onto it, a new shape
// (the rings of a sheet are one shape; apples of varied sizes and squash are many).
void add_to_kind(const ElementStructure& e, const TriMesh& part, SwatchKind& kind,
                 KindSamples& samples) {
  ++kind.elements;
  kind.rings += e.ring_shaped ? 1 : 0;
  kind.long_elements += e.long_element ? 1 : 0;
  if (e.ring && !e.degenerate()) count_in(samples.histogram, e.links);
  if (e.ring_shaped) samples.folds.push_back(e.fold);
  Vector3d s;
  Eigen::Matrix3d axes;
  principal_extents(part.V, s, &axes);
  for (int a = 0; a < 3; ++a) samples.extents[a].push_back(s(a));
  const MatrixX3d centred = part.V.rowwise() - part.V.colwise().mean();
  int same_count = 0;
  bool known = false;
  for (const SwatchKind::Shape& shape : kind.shapes) {
    if (shape.V.rows() != centred.rows()) continue;
    ++same_count;
    if (similarity_residual(shape.V, centred) < 1e-8) {
      known = true;
      break;
    }
  }
  if (!known && same_count < 16) kind.shapes.push_back({centred, axes.leftCols<2>()});
}

// Classes of translates: elements of one kind whose vertices are equal up to a translation (to
// 1e-4 of the median element), numbered in order of first member. The copies of one element
// of the sheet a swatch repeats.
std::vector<int> translate_classes(const StructureReport& r, const std::vector<TriMesh>& parts) {
  const int n = static_cast<int>(r.elements.size());
  const double tol = 1e-4 * std::max(r.median_size, 1e-12);
  std::vector<int> cls(static_cast<size_t>(n), -1);
  std::vector<int> reps;  // an element of each class
  const auto translates = [&](int a, int b) {
    const MatrixX3d& A = parts[static_cast<size_t>(a)].V;
    const MatrixX3d& B = parts[static_cast<size_t>(b)].V;
    if (A.rows() != B.rows() || A.rows() == 0) return false;
    const Eigen::RowVector3d shift = B.row(0) - A.row(0);
    for (Eigen::Index v = 1; v < A.rows(); ++v)
      if ((B.row(v) - A.row(v) - shift).cwiseAbs().maxCoeff() > tol) return false;
    return true;
  };
  for (int i = 0; i < n; ++i) {
    for (size_t c = 0; c < reps.size() && cls[i] < 0; ++c)
      if (r.elements[static_cast<size_t>(reps[c])].kind == r.elements[i].kind &&
          translates(reps[c], i))
        cls[i] = static_cast<int>(c);
    if (cls[i] < 0) {
      cls[i] = static_cast<int>(reps.size());
      reps.push_back(i);
    }
  }
  return cls;
}

// Per ring that is not degenerate, the links an interior copy of it has in the sheet the swatch
// repeats: every copy of a class of translates links the union of the class's partners
// (offsets to their centres). A sheet two rings wide has no ring with all of its links (the
// square 4-in-1 pattern's flat rings showed 3 of their 4), but together its translates show
// them all. -1 for the others.
std::vector<int> repeated_link_counts(const StructureReport& r, const std::vector<int>& cls) {
  const int n = static_cast<int>(r.elements.size());
  const int classes = n ? *std::max_element(cls.begin(), cls.end()) + 1 : 0;
  // Offsets equal within a tenth of a ring are one partner (two rings never share a place; a
  // partner's own class does not matter: a ring moved out of its class still stands where its
  // copies would).
  std::vector<std::vector<Vector3d>> partners(static_cast<size_t>(classes));
  const double same = 0.1 * r.median_size;
  const auto add = [&](int a, int b) {
    const Vector3d d =
        r.elements[static_cast<size_t>(b)].centre - r.elements[static_cast<size_t>(a)].centre;
    std::vector<Vector3d>& list = partners[static_cast<size_t>(cls[a])];
    for (const Vector3d& p : list)
      if ((p - d).norm() <= same) return;
    list.push_back(d);
  };
  for (const auto& [a, b] : r.linked_pairs) {
    add(a, b);
    add(b, a);
  }
  std::vector<int> out(static_cast<size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    const ElementStructure& e = r.elements[static_cast<size_t>(i)];
    if (e.ring && !e.degenerate())
      out[i] = static_cast<int>(partners[static_cast<size_t>(cls[i])].size());
  }
  return out;
}

// A class of translates as a lattice in the swatch plane: from the member nearest the class's
// mean centre, the shortest offset to another member (v1) and the shortest not parallel to it
// (v2), a reduced basis when every offset is a whole combination of the two (to a tenth).
// rows: 0 a lone element or no lattice, 1 the members in one row (v1 only), 2 a basis.
struct ClassLattice {
  int rows = 0;
  Vector2d v1 = Vector2d::Zero(), v2 = Vector2d::Zero();
  double area() const { return std::abs(v1.x() * v2.y() - v1.y() * v2.x()); }  // of a basis
  // Whether d is a whole combination of the basis (to a tenth).
  bool holds(const Vector2d& d) const {
    Eigen::Matrix2d basis;
    basis << v1, v2;
    const Vector2d c = basis.inverse() * d;
    return (c - c.array().round().matrix()).cwiseAbs().maxCoeff() <= 0.1;
  }
};

ClassLattice class_lattice(const std::vector<Vector2d>& members) {
  ClassLattice out;
  if (members.size() < 2) return out;
  Vector2d mean = Vector2d::Zero();
  for (const Vector2d& p : members) mean += p;
  mean /= static_cast<double>(members.size());
  size_t k = 0;
  for (size_t i = 1; i < members.size(); ++i)
    if ((members[i] - mean).norm() < (members[k] - mean).norm()) k = i;
  std::vector<Vector2d> offsets;
  for (size_t i = 0; i < members.size(); ++i)
    if (i != k) offsets.push_back(members[i] - members[k]);
  std::stable_sort(offsets.begin(), offsets.end(),
                   [](const Vector2d& a, const Vector2d& b) { return a.norm() < b.norm(); });
  out.v1 = offsets.front();
  if (!(out.v1.norm() > 0)) return out;
  for (const Vector2d& d : offsets)
    if (std::abs(out.v1.x() * d.y() - out.v1.y() * d.x()) > 0.2 * out.v1.norm() * d.norm()) {
      out.v2 = d;
      break;
    }
  if (out.v2.norm() > 0) {
    for (const Vector2d& d : offsets)
      if (!out.holds(d)) return {};
    out.rows = 2;
    return out;
  }
  for (const Vector2d& d : offsets) {  // one row: every offset a whole number of v1
    const double c = d.dot(out.v1) / out.v1.squaredNorm();
    if (std::abs(c - std::round(c)) > 0.1) return {};
  }
  out.rows = 1;
  return out;
}

// Elements per unit area of the sheet the swatch repeats: one per lattice cell of each class of
// translates. A class in one row (the connectors between the two rows of a sheet two rings
// wide) takes the cell of a class with a basis of which its row's period is a vector. 0 when a
// class has neither (a swatch of unique elements: apples) or no class has a basis.
double class_lattice_density(const StructureReport& r, const std::vector<int>& cls) {
  const int classes = cls.empty() ? 0 : *std::max_element(cls.begin(), cls.end()) + 1;
  std::vector<std::vector<Vector2d>> members(static_cast<size_t>(classes));
  for (size_t i = 0; i < cls.size(); ++i)
    members[static_cast<size_t>(cls[i])].push_back(r.elements[i].centre.head<2>());
  std::vector<ClassLattice> lattices(members.size());
  std::transform(members.begin(), members.end(), lattices.begin(), class_lattice);
  double density = 0;
  for (const ClassLattice& l : lattices) {
    const ClassLattice* cell = l.rows == 2 ? &l : nullptr;
    for (const ClassLattice& o : lattices)  // a row takes the cell of a basis holding its period
      if (!cell && l.rows == 1 && o.rows == 2 && o.holds(l.v1)) cell = &o;
    if (!cell) return 0;
    density += 1 / cell->area();
  }
  return density;
}

// Per kind: ring-ness, link count, fold, extents and the distinct shapes of its elements; and
// each element's class of translates (cls).
std::vector<SwatchKind> swatch_kinds(const TriMesh& mesh, const StructureReport& r,
                                     std::vector<int>& cls) {
  std::vector<int> fc;
  const int ne = connected_components(mesh.F, mesh.num_vertices(), fc);
  const std::vector<std::vector<int>> groups = component_faces(fc, ne);
  std::vector<SwatchKind> kinds(r.kinds.size());
  std::vector<KindSamples> samples(r.kinds.size());
  for (size_t k = 0; k < r.kinds.size(); ++k) kinds[k].name = r.kinds[k];
  std::vector<TriMesh> parts(static_cast<size_t>(ne));
  for (int c = 0; c < ne; ++c) {
    const ElementStructure& e = r.elements[static_cast<size_t>(c)];
    const size_t k = static_cast<size_t>(e.kind);
    parts[static_cast<size_t>(c)] = extract_faces(mesh, groups[static_cast<size_t>(c)]);
    add_to_kind(e, parts[static_cast<size_t>(c)], kinds[k], samples[k]);
  }
  // Judged as in the sheet the swatch repeats (a ring's count in it is never below its own).
  cls = translate_classes(r, parts);
  const std::vector<int> repeated = repeated_link_counts(r, cls);
  std::vector<std::vector<int>> repeated_histogram(kinds.size());
  for (int c = 0; c < ne; ++c) {
    const int links = repeated[static_cast<size_t>(c)];
    if (links >= 0) count_in(repeated_histogram[static_cast<size_t>(r.elements[c].kind)], links);
  }
  for (size_t k = 0; k < kinds.size(); ++k) {
    SwatchKind& kind = kinds[k];
    kind.ring = 2 * kind.rings > kind.elements;
    kind.compact = 2 * kind.long_elements <= kind.elements;
    int judged = 0;
    for (const int h : samples[k].histogram) judged += h;
    if (kind.ring)
      kind.interior_links = std::max(common_count(samples[k].histogram, judged),
                                     common_count(repeated_histogram[k], judged));
    kind.fold = median(samples[k].folds);
    for (int a = 0; a < 3; ++a) kind.extents(a) = median(samples[k].extents[a]);
  }
  return kinds;
}

// The element centres in the swatch plane (z is the thickness axis after prepare_swatch), with
// their box and each one's neighbours within four spacings (they bound every cell that closes
// at all in a sheet).
class SwatchCentres {
 public:
  explicit SwatchCentres(const StructureReport& r)
      : n_(static_cast<int>(r.elements.size())),
        c_(static_cast<size_t>(n_)),
        radius_(4 * (r.median_spacing > 0 ? r.median_spacing : r.median_size)),
        grid_(std::max(radius_, 1e-12)) {
    lo_ = Vector2d::Constant(std::numeric_limits<double>::infinity());
    hi_ = -lo_;
    for (int i = 0; i < n_; ++i) {
      c_[i] = r.elements[i].centre.head<2>();
      lo_ = lo_.cwiseMin(c_[i]);
      hi_ = hi_.cwiseMax(c_[i]);
    }
    for (int i = 0; i < n_; ++i)
      grid_.insert_box(i, Vector3d(c_[i].x(), c_[i].y(), 0), Vector3d(c_[i].x(), c_[i].y(), 0));
  }
  std::vector<int> near(int i) const {
    const Vector3d p(c_[i].x(), c_[i].y(), 0), d(radius_, radius_, 0);
    std::vector<int> ids;
    for (const int j : grid_.query_box(p - d, p + d))
      if (j != i && (c_[j] - c_[i]).norm() <= radius_) ids.push_back(j);
    return ids;
  }
  // The mean area of the Voronoi cells that close inside the centres' box: elements per unit
  // area, 0 when no cell closes.
  double closed_cell_density() const {
    const double tol = 1e-9 * std::max(1.0, (hi_ - lo_).norm());
    double closed_area = 0;
    int closed = 0;
    for (int i = 0; i < n_ && n_ > 1; ++i) {
      std::vector<Vector2d> cell = {lo_, Vector2d(hi_.x(), lo_.y()), hi_,
                                    Vector2d(lo_.x(), hi_.y())};
      for (const int j : near(i)) {
        if (cell.empty()) break;
        cell = clip(cell, 0.5 * (c_[i] + c_[j]), c_[j] - c_[i]);
      }
      bool inside = cell.size() >= 3;
      for (const Vector2d& p : cell)
        if (p.x() <= lo_.x() + tol || p.y() <= lo_.y() + tol || p.x() >= hi_.x() - tol ||
            p.y() >= hi_.y() - tol)
          inside = false;
      if (!inside) continue;
      closed_area += polygon_area(cell);
      ++closed;
    }
    return closed > 0 && closed_area > 0 ? closed / closed_area : 0;
  }
  // 1 / the median area of the parallelogram of each centre's two nearest independent
  // neighbours (exact for a lattice); 0 when there is none.
  double lattice_cell_density() const {
    std::vector<double> cells;
    for (int i = 0; i < n_; ++i) {
      std::vector<std::pair<double, int>> byd;
      for (const int j : near(i)) byd.emplace_back((c_[j] - c_[i]).norm(), j);
      std::sort(byd.begin(), byd.end());
      if (byd.empty()) continue;
      const Vector2d v1 = c_[byd[0].second] - c_[i];
      for (size_t k = 1; k < byd.size(); ++k) {
        const Vector2d v2 = c_[byd[k].second] - c_[i];
        const double cross = std::abs(v1.x() * v2.y() - v1.y() * v2.x());
        if (cross > 0.2 * v1.norm() * v2.norm()) {
          cells.push_back(cross);
          break;
        }
      }
    }
    const double m = median(cells);
    return m > 0 ? 1.0 / m : 0;
  }

 private:
  int n_;
  std::vector<Vector2d> c_;
  Vector2d lo_, hi_;
  double radius_;
  HashGrid3 grid_;
};

}  // namespace

SwatchStructure measure_swatch_structure(const TriMesh& swatch) {
  SwatchStructure out;
  const PreparedSwatch prepared = prepare_swatch(swatch);
  StructureOptions own;
  own.judge_folds = false;  // its rings are the reference
  out.report = measure_structure(prepared.mesh, own);
  const StructureReport& r = out.report;
  out.interior_links = common_count(r.link_histogram, r.rings - r.degenerate_rings());
  std::vector<int> cls;
  out.kinds = swatch_kinds(prepared.mesh, r, cls);
  // Density: of a swatch whose elements are copies on lattices, that of the sheet it repeats
  // (exact: the square 4-in-1 sheet two rings wide measured 0.427 by its Voronoi cells, its
  // sheet has 3 / 2.5^2 = 0.48); else from the Voronoi cells in the swatch plane, or when no
  // cell closes (a sheet two elements wide), the lattice cell of each centre's nearest
  // neighbours.
  out.density = class_lattice_density(r, cls);
  if (out.density > 0) return out;
  const SwatchCentres centres(r);
  out.density = centres.closed_cell_density();
  if (!(out.density > 0)) out.density = centres.lattice_cell_density();
  return out;
}

StructureComparison compare_structure(const StructureReport& output, const SwatchStructure& swatch,
                                      double linear_scale) {
  StructureComparison c;
  c.interior_links = swatch.interior_links;
  c.linear_scale = linear_scale > 0          ? linear_scale
                   : output.linear_scale > 0 ? output.linear_scale
                   : swatch.report.median_area > 0
                       ? std::sqrt(output.median_area / swatch.report.median_area)
                       : 0;
  // Each interior ring against its own swatch kind's count.
  const int nk = static_cast<int>(swatch.kinds.size());
  std::vector<KindComparison> per(static_cast<size_t>(nk));
  int judged = 0, matching = 0, loop_matching = 0;
  for (const ElementStructure& e : output.elements) {
    if (!e.ring || !e.interior) continue;
    const int sk = e.swatch_kind >= 0 ? e.swatch_kind
                   : nk > 0 ? swatch_kind_for(swatch, output.kinds[static_cast<size_t>(e.kind)],
                                              e.vertices, true)
                            : -1;
    const int expected = sk >= 0 && swatch.kinds[sk].interior_links >= 0
                             ? swatch.kinds[sk].interior_links
                             : swatch.interior_links;
    const bool match = !e.degenerate() && e.links == expected;
    ++judged;
    matching += match ? 1 : 0;
    loop_matching += e.ring_shaped && e.loop_links == expected ? 1 : 0;
    if (sk < 0) continue;
    KindComparison& k = per[static_cast<size_t>(sk)];
    k.interior_links = expected;
    ++k.interior_rings;
    k.matching += match ? 1 : 0;
    k.degenerate += e.degenerate() ? 1 : 0;
  }
  c.share_matching = judged > 0 ? static_cast<double>(matching) / judged : 0;
  c.share_counting_degenerate = judged > 0 ? static_cast<double>(loop_matching) / judged : 0;
  for (int k = 0; k < nk; ++k) {
    KindComparison& kc = per[static_cast<size_t>(k)];
    if (kc.interior_rings == 0) continue;
    kc.kind = swatch.kinds[static_cast<size_t>(k)].name;
    kc.share = static_cast<double>(kc.matching) / kc.interior_rings;
    c.kinds.push_back(kc);
  }
  const StructureReport& sr = swatch.report;
  if (output.median_long_length > 0 && sr.median_long_length > 0 && c.linear_scale > 0) {
    c.long_length_ratio = output.median_long_length / (sr.median_long_length * c.linear_scale);
    if (output.long_length > 0 && sr.long_length > 0 && sr.compact_elements > 0)
      c.compact_per_length_ratio = (output.compact_elements / output.long_length) /
                                   (sr.compact_elements / (sr.long_length * c.linear_scale));
  }
  const bool long_swatch =
      2 * swatch.report.long_elements > static_cast<int>(swatch.report.elements.size());
  if (output.density > 0 && swatch.density > 0 && c.linear_scale > 0 && !long_swatch)
    c.density_ratio = output.density / (swatch.density / (c.linear_scale * c.linear_scale));
  if (c.linear_scale > 0 && output.long_elements > 0 && output.area > 0)
    c.interior_ends_per_swatch_area =
        output.interior_ends_per_area * c.linear_scale * c.linear_scale;
  // Shapes, measured with the swatch (measure_structure's options.swatch).
  std::vector<double> sizes, aspects;
  for (const ElementStructure& e : output.elements) {
    if (!(e.size_ratio > 0)) continue;
    sizes.push_back(e.size_ratio);
    aspects.push_back(e.aspect);
    c.shape.by_correspondence += e.by_correspondence ? 1 : 0;
    c.largest_stretch = std::max(c.largest_stretch, e.stretch);
    c.stretched += e.stretch > StructureComparison::kStretchedSize ? 1 : 0;
  }
  std::sort(sizes.begin(), sizes.end());
  std::sort(aspects.begin(), aspects.end());
  ShapeSummary& s = c.shape;
  s.elements = static_cast<int>(sizes.size());
  s.size_median = percentile(sizes, 0.5);
  s.size_p90 = percentile(sizes, 0.9);
  s.size_p99 = percentile(sizes, 0.99);
  s.size_max = sizes.empty() ? 0 : sizes.back();
  s.aspect_median = percentile(aspects, 0.5);
  s.aspect_p90 = percentile(aspects, 0.9);
  s.aspect_max = aspects.empty() ? 0 : aspects.back();
  return c;
}

StructureSummary summarize_structure(const TriMesh& output, const TriMesh& swatch,
                                     const TriMesh* base, double linear_scale) {
  StructureSummary out;
  StructureOptions so;
  std::unique_ptr<ClosestPointQuery> query;
  MatrixX3d normals;
  if (base) {
    so.automatic_border = false;
    so.border = mesh_border(base->V, base->F);
    so.area = surface_area(base->V, base->F);
    query = std::make_unique<ClosestPointQuery>(base->V, base->F);
    normals = face_normals(base->V, base->F);
    so.surface_normal = [&](const Vector3d& p) -> Vector3d {
      return normals.row(query->closest(p).face).transpose();
    };
  }
  out.swatch = measure_swatch_structure(swatch);
  so.swatch = &out.swatch;
  so.linear_scale = linear_scale;
  out.output = measure_structure(output, so);
  out.comparison = compare_structure(out.output, out.swatch, linear_scale);
  return out;
}

}  // namespace mq
