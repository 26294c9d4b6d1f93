#include "core/mesh/quadric_simplification.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

namespace {

// Sum of squared distances to planes: a symmetric 4 by 4 matrix, its upper triangle in order
// xx xy xz xw yy yz yw zz zw ww.
struct Quadric {
  double q[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  // The plane n . x + d = 0, |n| = 1.
  void add_plane(const Vector3d& n, double d) {
    q[0] += n.x() * n.x(), q[1] += n.x() * n.y(), q[2] += n.x() * n.z(), q[3] += n.x() * d;
    q[4] += n.y() * n.y(), q[5] += n.y() * n.z(), q[6] += n.y() * d;
    q[7] += n.z() * n.z(), q[8] += n.z() * d, q[9] += d * d;
  }
  void add(const Quadric& o) {
    for (int i = 0; i < 10; ++i) q[i] += o.q[i];
  }
  double at(const Vector3d& p) const {
    const double x = p.x(), y = p.y(), z = p.z();
    const double e = q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x +
                     q[4] * y * y + 2 * q[5] * y * z + 2 * q[6] * y + q[7] * z * z + 2 * q[8] * z +
                     q[9];
    return std::max(e, 0.0);
  }
};

// An edge (a < b), tried with the cheaper of its two half-edge collapses first.
struct Candidate {
  int a, b;
  unsigned stamp_a, stamp_b;
};

// Candidates by error in buckets a factor sqrt(2) apart (error 0 in the first), each served in
// the order filled: the cheapest bucket first, as a heap would, without a heap's cache misses
// over millions of entries (a 1.1M-face base: 4.0 -> 2.75 s of CPU). Within a bucket the
// errors differ by less than the factor, so the order of collapses is the heap's up to that.
class CandidateQueue {
 public:
  explicit CandidateQueue(double max_cost) : max_cost_(max_cost) {}
  void push(double cost, const Candidate& c) {
    const size_t b = bucket(cost);
    buckets_[b].push_back(c);
    lowest_ = std::min(lowest_, b);
  }
  bool pop(Candidate& c) {
    for (; lowest_ < kBuckets; ++lowest_) {
      std::vector<Candidate>& q = buckets_[lowest_];
      size_t& next = next_[lowest_];
      if (next < q.size()) {
        c = q[next++];
        if (next == q.size()) q.clear(), next = 0;
        return true;
      }
    }
    return false;
  }

 private:
  static constexpr size_t kBuckets = 130;
  size_t bucket(double cost) const {
    if (!(cost > 0) || !(max_cost_ > 0)) return 0;
    // cost / max_cost in (0, 1]: each halving of it one bucket down (in squared distance, so
    // sqrt(2) in distance), 2^-128 and below all in bucket 1.
    const double steps = -std::log2(cost / max_cost_);
    return kBuckets - 1 - std::min<size_t>(kBuckets - 2, static_cast<size_t>(steps));
  }
  double max_cost_;
  std::vector<Candidate> buckets_[kBuckets];
  size_t next_[kBuckets] = {};
  size_t lowest_ = kBuckets;
};

// 4 sqrt(3) area / (sum of squared edge lengths): 1 for an equilateral triangle, 0 for a
// degenerate one.
double quality(const Vector3d c[3]) {
  const double area2 = (c[1] - c[0]).cross(c[2] - c[0]).norm();  // twice the area
  const double edges =
      (c[1] - c[0]).squaredNorm() + (c[2] - c[1]).squaredNorm() + (c[0] - c[2]).squaredNorm();
  return edges > 0 ? 2 * std::sqrt(3.0) * area2 / edges : 0;
}

// The state of one simplification: the faces as they collapse, the quadric per vertex, the
// locked vertices and the queue of candidate edges.
class QuadricCollapser {
 public:
  QuadricCollapser(const TriMesh& mesh, const QuadricSimplificationOptions& options)
      : mesh_(mesh),
        options_(options),
        F_(mesh.F),
        face_alive_(static_cast<size_t>(mesh.num_faces()), 1),
        vertex_alive_(static_cast<size_t>(mesh.num_vertices()), 1),
        faces_of_(static_cast<size_t>(mesh.num_vertices())),
        Q_(static_cast<size_t>(mesh.num_vertices())),
        stamp_(static_cast<size_t>(mesh.num_vertices()), 0),
        cos_turn_(std::cos(options.max_normal_turn_degrees * M_PI / 180)),
        max_error2_(options.max_error * options.max_error),
        max_edge2_(options.max_edge_length * options.max_edge_length),
        queue_(max_error2_) {
    // Quadrics about the box centre: far from the origin the expanded form would lose the
    // small errors to cancellation.
    const BoundingBox box = bounding_box(mesh.V, mesh.F);
    centre_ = box.empty() ? Vector3d::Zero() : box.center();
  }

  // The face lists, the vertex quadrics (Garland and Heckbert's sum of face planes), the locked
  // vertices and every edge within the error as a candidate.
  void prepare() {
    const int nv = mesh_.num_vertices(), nf = mesh_.num_faces();
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) faces_of_[F_(f, k)].push_back(f);
    for (int f = 0; f < nf; ++f) {
      const Vector3d a = P(F_(f, 0)), b = P(F_(f, 1)), c = P(F_(f, 2));
      Vector3d n = (b - a).cross(c - a);
      if (!(n.norm() > 0)) continue;
      n.normalize();
      for (int k = 0; k < 3; ++k) Q_[F_(f, k)].add_plane(n, -n.dot(a));
    }
    // Vertices that stay: on a boundary or non-manifold edge, or where pieces of surface touch
    // (more than one fan: the disk condition fails).
    const EdgeTopology topo = edge_topology(mesh_.F, nv);
    locked_ = multi_fan_vertices(mesh_.F, nv, topo);
    for (int e = 0; e < topo.num_edges(); ++e)
      if (topo.edge_faces.degree(e) != 2) locked_[topo.E(e, 0)] = locked_[topo.E(e, 1)] = 1;
    for (const int v : options_.kept_vertices) locked_[v] = 1;
    for (int e = 0; e < topo.num_edges(); ++e) push(topo.E(e, 0), topo.E(e, 1));
  }

  // Collapses candidates cheapest first while the error stays within bounds.
  void run(QuadricSimplification& out) {
    Candidate c;
    int faces = mesh_.num_faces();
    while (faces > options_.target_faces && queue_.pop(c)) {
      if (!vertex_alive_[c.a] || !vertex_alive_[c.b]) continue;
      if (c.stamp_a != stamp_[c.a] || c.stamp_b != stamp_[c.b]) continue;
      // The cheaper direction first (ties: the lower index goes), then the other.
      const double ab = cost_of(c.a, c.b), ba = cost_of(c.b, c.a);
      const std::pair<int, int> order[2] = {
          ab <= ba ? std::make_pair(c.a, c.b) : std::make_pair(c.b, c.a),
          ab <= ba ? std::make_pair(c.b, c.a) : std::make_pair(c.a, c.b)};
      int from = -1, to = -1, shared[2] = {-1, -1};
      double cost = 0;
      for (const auto& [f, t] : order) {
        cost = f == c.a ? ab : ba;
        if (cost <= max_error2_ && can_collapse(f, t, shared)) {
          from = f;
          to = t;
          break;
        }
      }
      if (from < 0) continue;
      collapse(from, to, shared);
      faces -= 2;
      ++out.collapses;
      out.max_error = std::max(out.max_error, std::sqrt(cost));
    }
  }

  // The kept faces in input order, the kept vertices in input order.
  void write_kept(QuadricSimplification& out) const {
    const int nv = mesh_.num_vertices(), nf = mesh_.num_faces();
    std::vector<int> index(static_cast<size_t>(nv), -1);
    for (int f = 0; f < nf; ++f)
      if (face_alive_[f]) out.origin_face.push_back(f);
    for (const int f : out.origin_face)
      for (int k = 0; k < 3; ++k) index[F_(f, k)] = 0;
    for (int v = 0; v < nv; ++v)
      if (index[v] == 0) {
        index[v] = static_cast<int>(out.origin_vertex.size());
        out.origin_vertex.push_back(v);
      }
    out.mesh.V.resize(static_cast<Eigen::Index>(out.origin_vertex.size()), 3);
    for (size_t i = 0; i < out.origin_vertex.size(); ++i)
      out.mesh.V.row(static_cast<Eigen::Index>(i)) = mesh_.V.row(out.origin_vertex[i]);
    out.mesh.F.resize(static_cast<Eigen::Index>(out.origin_face.size()), 3);
    for (size_t i = 0; i < out.origin_face.size(); ++i)
      for (int k = 0; k < 3; ++k)
        out.mesh.F(static_cast<Eigen::Index>(i), k) = index[F_(out.origin_face[i], k)];
    out.mesh.kinds = mesh_.kinds;
    if (!mesh_.face_kind.empty())
      for (const int f : out.origin_face) out.mesh.face_kind.push_back(mesh_.face_kind[f]);
  }

 private:
  // A vertex position relative to the centre (the short name keeps the formulas readable).
  Vector3d P(int v) const {  // NOLINT(readability-identifier-naming)
    return mesh_.V.row(v).transpose() - centre_;
  }
  std::vector<int> neighbours(int v) const {
    std::vector<int> n;
    for (const int f : faces_of_[v])
      for (int k = 0; k < 3; ++k)
        if (F_(f, k) != v) n.push_back(F_(f, k));
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
    return n;
  }
  bool has_vertex(int f, int v) const { return F_(f, 0) == v || F_(f, 1) == v || F_(f, 2) == v; }
  // The error of `from` going into `to` (infinite when `from` must stay).
  double cost_of(int from, int to) const {
    if (locked_[from]) return kInf;
    Quadric sum = Q_[from];
    sum.add(Q_[to]);
    return sum.at(P(to));
  }
  void push(int a, int b) {
    if (a > b) std::swap(a, b);
    const double cost = std::min(cost_of(a, b), cost_of(b, a));
    if (cost > max_error2_) return;
    queue_.push(cost, {a, b, stamp_[a], stamp_[b]});
  }

  // Can `from` go into `to`? (both alive, `from` not locked) `shared` receives the two faces
  // the edge removes.
  bool can_collapse(int from, int to, int shared[2]) const {
    int count = 0;
    for (const int f : faces_of_[from])
      if (has_vertex(f, to)) {
        if (count == 2) return false;
        shared[count++] = f;
      }
    if (count != 2 || !link_condition(from, to, shared)) return false;
    for (const int f : faces_of_[from])
      if (f != shared[0] && f != shared[1] && !face_stays_valid(f, from, to, shared)) return false;
    return true;
  }
  // The surface stays a manifold: the two ends share exactly the two opposite corners as
  // neighbours.
  bool link_condition(int from, int to, const int shared[2]) const {
    std::vector<int> opposite;
    for (int s = 0; s < 2; ++s)
      for (int k = 0; k < 3; ++k) {
        const int w = F_(shared[s], k);
        if (w != from && w != to) opposite.push_back(w);
      }
    if (opposite.size() != 2 || opposite[0] == opposite[1]) return false;
    std::sort(opposite.begin(), opposite.end());
    const std::vector<int> nf = neighbours(from), nt = neighbours(to);
    std::vector<int> common;
    std::set_intersection(nf.begin(), nf.end(), nt.begin(), nt.end(), std::back_inserter(common));
    return common == opposite;
  }
  // Face f of `from`, its corner moved to `to`: it neither flips nor turns too far, is no new
  // sliver, has no edge too long and repeats no face of `to`.
  bool face_stays_valid(int f, int from, int to, const int shared[2]) const {
    const Vector3d pt = P(to);
    Vector3d old_c[3], new_c[3];
    int others[2] = {-1, -1}, m = 0;
    for (int k = 0; k < 3; ++k) {
      const int w = F_(f, k);
      old_c[k] = P(w);
      new_c[k] = w == from ? pt : old_c[k];
      if (w != from) others[m++] = w;
    }
    const Vector3d n_old = (old_c[1] - old_c[0]).cross(old_c[2] - old_c[0]);
    const Vector3d n_new = (new_c[1] - new_c[0]).cross(new_c[2] - new_c[0]);
    const double lo = n_old.norm(), ln = n_new.norm();
    if (!(ln > 1e-12 * std::max(lo, 1e-300))) return false;
    if (n_new.dot(n_old) < cos_turn_ * lo * ln) return false;
    // No sliver where there was none: a long thin face can lie within the error of a curved
    // surface and still turn its normal far from it (the shell grows along those normals).
    if (quality(new_c) < std::min(options_.min_quality, quality(old_c))) return false;
    for (const int w : others)
      if ((P(w) - pt).squaredNorm() > max_edge2_) return false;
    for (const int g : faces_of_[to]) {
      if (g == shared[0] || g == shared[1]) continue;
      if (has_vertex(g, others[0]) && has_vertex(g, others[1])) return false;
    }
    return true;
  }
  // The half-edge collapse: the shared faces go, `from`'s faces take `to`, and the edges
  // round `to` are candidates again.
  void collapse(int from, int to, const int shared[2]) {
    for (int s = 0; s < 2; ++s) {
      face_alive_[shared[s]] = 0;
      for (int k = 0; k < 3; ++k) {
        std::vector<int>& list = faces_of_[F_(shared[s], k)];
        list.erase(std::remove(list.begin(), list.end(), shared[s]), list.end());
      }
    }
    for (const int f : faces_of_[from]) {
      for (int k = 0; k < 3; ++k)
        if (F_(f, k) == from) F_(f, k) = to;
      faces_of_[to].push_back(f);
    }
    faces_of_[from].clear();
    vertex_alive_[from] = 0;
    Q_[to].add(Q_[from]);
    ++stamp_[to];
    for (const int w : neighbours(to)) push(to, w);
  }

  const TriMesh& mesh_;
  const QuadricSimplificationOptions& options_;
  Vector3d centre_;
  MatrixX3i F_;
  std::vector<char> face_alive_, vertex_alive_, locked_;
  std::vector<std::vector<int>> faces_of_;
  std::vector<Quadric> Q_;
  std::vector<unsigned> stamp_;
  const double cos_turn_, max_error2_, max_edge2_;
  CandidateQueue queue_;
};

}  // namespace

void QuadricSimplificationOptions::validate() const {
  MQ_CHECK(std::isfinite(max_error) && max_error >= 0, InvalidInput,
           "simplification: the largest error must be finite and not negative, got ", max_error);
  MQ_CHECK(max_edge_length > 0, InvalidInput,
           "simplification: the longest edge must be positive, got ", max_edge_length);
  MQ_CHECK(min_quality >= 0 && min_quality <= 1, InvalidInput,
           "simplification: the lowest face quality must be in [0, 1], got ", min_quality);
  MQ_CHECK(max_normal_turn_degrees > 0 && max_normal_turn_degrees < 180, InvalidInput,
           "simplification: the largest normal turn must be in (0, 180) degrees, got ",
           max_normal_turn_degrees);
  MQ_CHECK(target_faces >= 0, InvalidInput,
           "simplification: the target face count must not be negative, got ", target_faces);
}

QuadricSimplification simplify_by_quadrics(const TriMesh& mesh,
                                           const QuadricSimplificationOptions& options) {
  options.validate();
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  MQ_CHECK(nf == 0 || (mesh.F.minCoeff() >= 0 && mesh.F.maxCoeff() < nv), InvalidInput,
           "simplification: face index out of range [0, ", nv, ")");
  MQ_CHECK(mesh.V.allFinite(), InvalidInput, "simplification: vertex positions are not finite");
  for (const int v : options.kept_vertices)
    MQ_CHECK(v >= 0 && v < nv, InvalidInput, "simplification: kept vertex ", v,
             " out of range [0, ", nv, ")");
  QuadricCollapser collapser(mesh, options);
  collapser.prepare();
  QuadricSimplification out;
  collapser.run(out);
  collapser.write_kept(out);
  return out;
}

}  // namespace mq
