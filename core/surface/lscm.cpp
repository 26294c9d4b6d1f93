#include "core/surface/lscm.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"

namespace mq {
namespace {

Vector3d vertex_row(const MatrixX3d& V, int i) { return V.row(i).transpose(); }

void check_patch_indices(const MatrixX3i& F, Eigen::Index n) {
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(F(f, k) >= 0 && F(f, k) < n, InvalidInput, "face ", f, " has vertex index ", F(f, k),
               " out of range [0, ", n, ")");
}

// Checks that F is a connected, manifold disk; returns its boundary loop.
std::vector<int> disk_boundary(const MatrixX3i& F, int n, const EdgeTopology& topo) {
  // Boundary edges traversed as in their face; each vertex needs in- and out-degree <= 1.
  std::vector<int> next(n, -1), in_count(n, 0);
  for (int e = 0; e < topo.num_edges(); ++e)
    MQ_CHECK(!topo.is_non_manifold(e), TopologyError, "lscm: edge (", topo.E(e, 0), ", ",
             topo.E(e, 1), ") is used by ", topo.edge_faces.degree(e), " faces");
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      if (!topo.is_boundary(topo.FE(f, k))) continue;
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      MQ_CHECK(next[a] < 0, TopologyError, "lscm: non-manifold boundary vertex ", a);
      next[a] = b;
      ++in_count[b];
    }
  int start = -1;
  for (int v = 0; v < n; ++v) {
    MQ_CHECK((next[v] >= 0 ? 1 : 0) == in_count[v], TopologyError,
             "lscm: non-manifold or inconsistently oriented boundary at vertex ", v);
    if (start < 0 && next[v] >= 0) start = v;
  }
  MQ_CHECK(start >= 0, TopologyError, "lscm: the patch has no boundary (closed surface)");
  std::vector<int> loop;
  for (int v = start; v != start || loop.empty(); v = next[v]) loop.push_back(v);
  const int boundary_edges =
      static_cast<int>(std::count_if(next.begin(), next.end(), [](int v) { return v >= 0; }));
  MQ_CHECK(static_cast<int>(loop.size()) == boundary_edges, TopologyError,
           "lscm: the patch has several boundary loops, expected one (a topological disk)");
  const int euler = n - topo.num_edges() + static_cast<int>(F.rows());
  MQ_CHECK(euler == 1, TopologyError, "lscm: the patch has Euler characteristic ", euler,
           ", expected 1 (a topological disk)");
  // Connected through edges: union-find over vertices.
  std::vector<int> root(n);
  for (int v = 0; v < n; ++v) root[v] = v;
  auto find_root = [&](int i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  int components = n;
  for (int e = 0; e < topo.num_edges(); ++e) {
    const int a = find_root(topo.E(e, 0)), b = find_root(topo.E(e, 1));
    if (a != b) root[std::max(a, b)] = std::min(a, b), --components;
  }
  MQ_CHECK(components == 1, TopologyError, "lscm: the patch has ", components,
           " connected components, expected one");
  // Each vertex's corners must form a single fan (no pinch): union the corners of a vertex
  // across every interior edge and count the fans per vertex.
  std::vector<int> parent(3 * F.rows());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto corner = [&](int f, int v) {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) return 3 * f + k;
    return -1;
  };
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (topo.edge_faces.degree(e) != 2) continue;
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    for (int s = 0; s < 2; ++s) {
      const int a = find(corner(f, topo.E(e, s))), b = find(corner(g, topo.E(e, s)));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<int> fan_root(n, -1);
  for (int c = 0; c < 3 * F.rows(); ++c) {
    const int v = F(c / 3, c % 3), r = find(c);
    MQ_CHECK(fan_root[v] < 0 || fan_root[v] == r, TopologyError, "lscm: vertex ", v,
             " is non-manifold (its faces form several fans)");
    fan_root[v] = r;
  }
  return loop;
}

// UV scaled about the origin (pin0) so that its total signed area equals area3d.
MatrixX2d rescaled_to_3d_area(MatrixX2d UV, const MatrixX3i& F, double area3d) {
  double area_uv = 0;
  for (int f = 0; f < F.rows(); ++f) {
    const Vector2d a = UV.row(F(f, 0)).transpose(), b = UV.row(F(f, 1)).transpose(),
                   c = UV.row(F(f, 2)).transpose();
    const Vector2d ab = b - a, ac = c - a;
    area_uv += 0.5 * (ab.x() * ac.y() - ab.y() * ac.x());
  }
  MQ_CHECK(area_uv > 0 && std::isfinite(area_uv), SolverFailure,
           "lscm: the conformal map has non-positive total area");
  UV *= std::sqrt(area3d / area_uv);
  return UV;
}

// Isometric unfolding of a developable patch (a plane, or planes folded along edges like the
// sides of a box): faces are laid out breadth first across shared edges from face 0, each
// congruent to its 3D triangle. nullopt when a vertex reached through two faces lands in two
// places (some interior vertex's angles do not sum to 2 pi: the patch is curved) or a face is
// degenerate. Returned with pin0 at the origin and pin1 on the +u axis.
std::optional<MatrixX2d> developable_unfolding(const MatrixX3d& V, const MatrixX3i& F,
                                               const EdgeTopology& topo, int pin0, int pin1) {
  const int n = static_cast<int>(V.rows()), nf = static_cast<int>(F.rows());
  const double extent = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  const double tolerance = 1e-9 * extent;
  MatrixX2d UV = MatrixX2d::Zero(n, 2);
  std::vector<char> placed(n, 0), reached(nf, 0);
  const auto length = [&](int a, int b) { return (vertex_row(V, a) - vertex_row(V, b)).norm(); };
  // c to the left of a -> b at its 3D distances from a and b; false if the face is degenerate.
  const auto place = [&](int a, int b, int c, Vector2d& out) {
    const Vector2d pa = UV.row(a).transpose(), pb = UV.row(b).transpose();
    const double ab = (pb - pa).norm(), ac = length(a, c), bc = length(b, c);
    if (!(ab > 0)) return false;
    const Vector2d e = (pb - pa) / ab, perp(-e.y(), e.x());
    const double x = (ac * ac - bc * bc + ab * ab) / (2 * ab), y2 = ac * ac - x * x;
    if (!(y2 > 0) || !std::isfinite(y2)) return false;
    out = pa + x * e + std::sqrt(y2) * perp;
    return true;
  };
  UV.row(F(0, 1)) << length(F(0, 0), F(0, 1)), 0.0;
  placed[F(0, 0)] = placed[F(0, 1)] = 1;
  Vector2d c2;
  if (!place(F(0, 0), F(0, 1), F(0, 2), c2)) return std::nullopt;
  UV.row(F(0, 2)) = c2.transpose();
  placed[F(0, 2)] = 1;
  std::vector<int> queue{0};
  reached[0] = 1;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int f = queue[head];
    for (int k = 0; k < 3; ++k) {
      const int e = topo.FE(f, k);
      if (topo.edge_faces.degree(e) != 2) continue;
      const int* fs = topo.edge_faces.begin(e);
      const int g = fs[0] == f ? fs[1] : fs[0];
      if (reached[g]) continue;
      reached[g] = 1;
      int j = 0;
      while (topo.FE(g, j) != e) ++j;
      const int a = F(g, j), b = F(g, (j + 1) % 3), c = F(g, (j + 2) % 3);
      if (!place(a, b, c, c2)) return std::nullopt;
      if (placed[c]) {
        if ((UV.row(c).transpose() - c2).norm() > tolerance) return std::nullopt;
      } else {
        UV.row(c) = c2.transpose();
        placed[c] = 1;
      }
      queue.push_back(g);
    }
  }
  // Each face reached is congruent to its triangle: two corners came from its neighbour and the
  // third was placed, or checked, at its 3D distances from them.
  if (static_cast<int>(queue.size()) != nf) return std::nullopt;
  const Vector2d origin = UV.row(pin0).transpose();
  const Vector2d axis = (UV.row(pin1).transpose() - origin).normalized();
  if (!axis.allFinite()) return std::nullopt;
  MatrixX2d out(n, 2);
  for (int i = 0; i < n; ++i) {
    const Vector2d d = UV.row(i).transpose() - origin;
    out.row(i) << d.dot(axis), axis.x() * d.y() - axis.y() * d.x();
  }
  return out;
}

// Every face of three distinct vertices, every vertex on a face, positions finite.
void validate_patch(const MatrixX3d& V, const MatrixX3i& F) {
  const int n = static_cast<int>(V.rows());
  const int nf = static_cast<int>(F.rows());
  MQ_CHECK(nf > 0, InvalidInput, "lscm: the patch has no faces");
  check_patch_indices(F, n);
  MQ_CHECK(V.allFinite(), InvalidInput, "lscm: non-finite vertex position");
  std::vector<char> used(n, 0);
  for (int f = 0; f < nf; ++f) {
    MQ_CHECK(F(f, 0) != F(f, 1) && F(f, 1) != F(f, 2) && F(f, 2) != F(f, 0), InvalidInput,
             "lscm: face ", f, " repeats a vertex");
    for (int k = 0; k < 3; ++k) used[F(f, k)] = 1;
  }
  for (int v = 0; v < n; ++v)
    MQ_CHECK(used[v], InvalidInput, "lscm: vertex ", v, " is used by no face");
}

// Pins: double sweep over the boundary for a far-apart pair (first farthest point wins ties).
std::pair<int, int> far_pins(const MatrixX3d& V, const std::vector<int>& boundary) {
  auto farthest = [&](int from) {
    int best = boundary[0];
    double best_d = -1;
    for (int v : boundary) {
      const double d = (vertex_row(V, v) - vertex_row(V, from)).squaredNorm();
      if (d > best_d) best_d = d, best = v;
    }
    return best;
  };
  const int pin1 = farthest(boundary[0]);
  return {farthest(pin1), pin1};
}

// The energy sum_T A_T |grad v - rot90(grad u)|^2 splits into the Dirichlet energies of u and v
// (cotangent weights) minus twice the signed area of the image, and that area is a sum over the
// boundary edges alone (Levy et al. 2002; Desbrun et al. 2002). Assembled that way u and v are
// coupled on the boundary only: the factor of the 2n x 2n system fills in like two Laplacians
// instead of a system coupled at every vertex, which is what made a large patch (a fine base,
// issue 14) cost several times more per face than a small one. Unknowns: u and v of every
// vertex but the two pins, whose values go to the right-hand side.
class ConformalSystem {
 public:
  ConformalSystem(int n, int pin0, int pin1, double pin_distance)
      : unknown_(static_cast<size_t>(n), -1), pin0_(pin0), pin1_(pin1) {
    for (int v = 0; v < n; ++v)
      if (v != pin0 && v != pin1) unknown_[v] = nu_++;
    pinned_[0] = Vector2d::Zero();
    pinned_[1] = Vector2d(pin_distance, 0);
    rhs_ = Eigen::VectorXd::Zero(2 * nu_);
  }

  // Face f's Dirichlet terms, and its boundary edges' signed-area terms.
  void add_face(const MatrixX3d& V, const MatrixX3i& F, const EdgeTopology& topo, int f) {
    const Vector3d P[3] = {vertex_row(V, F(f, 0)), vertex_row(V, F(f, 1)), vertex_row(V, F(f, 2))};
    const double twice_area = (P[1] - P[0]).cross(P[2] - P[0]).norm();
    MQ_CHECK(twice_area > 0 && std::isfinite(twice_area), InvalidInput, "lscm: face ", f,
             " has zero area");
    for (int k = 0; k < 3; ++k) {
      // Edge (i, j) opposite corner k: Dirichlet weight cot(angle at k) / 2 on (u_i - u_j)^2
      // and (v_i - v_j)^2.
      const int i = F(f, (k + 1) % 3), j = F(f, (k + 2) % 3);
      const Vector3d a = P[(k + 1) % 3] - P[k], b = P[(k + 2) % 3] - P[k];
      const double w = 0.5 * a.dot(b) / twice_area;
      for (int c = 0; c < 2; ++c) {
        add(i, c, i, c, 0.5 * w);  // the diagonal is added twice by add
        add(j, c, j, c, 0.5 * w);
        add(i, c, j, c, -w);
      }
    }
    for (int k = 0; k < 3; ++k) {
      // -2 x signed area: -(u_i v_j - u_j v_i) per boundary edge i -> j in its face's order.
      if (!topo.is_boundary(topo.FE(f, k))) continue;
      const int i = F(f, k), j = F(f, (k + 1) % 3);
      add(i, 0, j, 1, -0.5);
      add(j, 0, i, 1, 0.5);
    }
  }

  // The minimiser: #V by 2, the pins at their values.
  MatrixX2d solve() const {
    const int n = static_cast<int>(unknown_.size());
    MatrixX2d UV(n, 2);
    UV.row(pin0_) = pinned_[0].transpose();
    UV.row(pin1_) = pinned_[1].transpose();
    if (nu_ == 0) return UV;
    Eigen::SparseMatrix<double> Q(2 * nu_, 2 * nu_);
    Q.setFromTriplets(triplets_.begin(), triplets_.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(Q);
    MQ_CHECK(solver.info() == Eigen::Success, SolverFailure,
             "lscm: factorisation of the conformal energy failed");
    const Eigen::VectorXd x = solver.solve(rhs_);
    MQ_CHECK(solver.info() == Eigen::Success && x.allFinite(), SolverFailure,
             "lscm: the conformal solve failed");
    for (int v = 0; v < n; ++v)
      if (unknown_[v] >= 0) UV.row(v) << x(unknown_[v]), x(nu_ + unknown_[v]);
    return UV;
  }

  void reserve(size_t triplets) { triplets_.reserve(triplets); }

 private:
  double value(int vertex, int coord) const {
    const Vector2d q = vertex == pin0_ ? pinned_[0] : pinned_[1];
    return coord == 0 ? q.x() : q.y();
  }
  // E(z) = z^T Q z over z = (u, v): adds q to Q(a, b) and Q(b, a), moving pinned terms to the
  // right-hand side of Q_ff z_f = -Q_fp z_p.
  void add(int va, int ca, int vb, int cb, double q) {
    const bool fa = unknown_[va] >= 0, fb = unknown_[vb] >= 0;
    const int ia = fa ? ca * nu_ + unknown_[va] : -1, ib = fb ? cb * nu_ + unknown_[vb] : -1;
    if (fa && fb) {
      triplets_.emplace_back(ia, ib, q);
      triplets_.emplace_back(ib, ia, q);
    } else if (fa) {
      rhs_(ia) -= q * value(vb, cb);
    } else if (fb) {
      rhs_(ib) -= q * value(va, ca);
    }
  }

  std::vector<int> unknown_;
  int nu_ = 0;
  const int pin0_, pin1_;
  Vector2d pinned_[2];
  std::vector<Eigen::Triplet<double>> triplets_;
  Eigen::VectorXd rhs_;
};

}  // namespace

MatrixX2d lscm(const MatrixX3d& V, const MatrixX3i& F) {
  validate_patch(V, F);
  const int n = static_cast<int>(V.rows());
  const int nf = static_cast<int>(F.rows());
  const EdgeTopology topo = edge_topology(F, n);
  const std::vector<int> boundary = disk_boundary(F, n, topo);
  const auto [pin0, pin1] = far_pins(V, boundary);
  const double pin_distance = (vertex_row(V, pin1) - vertex_row(V, pin0)).norm();
  MQ_CHECK(pin_distance > 0, InvalidInput, "lscm: the patch boundary has zero extent");

  // Total 3D area, summed in face order (the scale both paths below are normalised to).
  double area3d = 0;
  {
    const Eigen::VectorXd A = face_areas(V, F);
    for (Eigen::Index f = 0; f < A.size(); ++f) area3d += A(f);
  }
  // A developable patch (a wall's panel, the folded sides of a pillar) has a zero-energy
  // conformal map, its isometric unfolding: up to the similarity the pins and the area fix, the
  // solution of the system below (unique for a connected disk with two pins), without a solve.
  if (const std::optional<MatrixX2d> flat = developable_unfolding(V, F, topo, pin0, pin1))
    return rescaled_to_3d_area(*flat, F, area3d);
  ConformalSystem system(n, pin0, pin1, pin_distance);
  system.reserve(static_cast<size_t>(nf) * 24);
  for (int f = 0; f < nf; ++f) system.add_face(V, F, topo, f);
  return rescaled_to_3d_area(system.solve(), F, area3d);
}

Eigen::VectorXd face_area_distortion(const MatrixX3d& V, const MatrixX3i& F, const MatrixX2d& UV) {
  MQ_CHECK(V.rows() == UV.rows(), InvalidInput, "face_area_distortion: ", V.rows(),
           " vertices but ", UV.rows(), " UV rows");
  check_patch_indices(F, V.rows());
  Eigen::VectorXd d(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    const Vector3d P0 = vertex_row(V, F(f, 0));
    const double a3 = 0.5 * (vertex_row(V, F(f, 1)) - P0).cross(vertex_row(V, F(f, 2)) - P0).norm();
    const Vector2d ab = (UV.row(F(f, 1)) - UV.row(F(f, 0))).transpose();
    const Vector2d ac = (UV.row(F(f, 2)) - UV.row(F(f, 0))).transpose();
    const double a2 = 0.5 * std::abs(ab.x() * ac.y() - ab.y() * ac.x());
    d(f) =
        (a3 > 0 && a2 > 0) ? std::max(a2 / a3, a3 / a2) : std::numeric_limits<double>::infinity();
  }
  return d;
}

int count_flipped(const MatrixX3i& F, const MatrixX2d& UV) {
  check_patch_indices(F, UV.rows());
  int flipped = 0;
  for (int f = 0; f < F.rows(); ++f) {
    const Vector2d ab = (UV.row(F(f, 1)) - UV.row(F(f, 0))).transpose();
    const Vector2d ac = (UV.row(F(f, 2)) - UV.row(F(f, 0))).transpose();
    if (ab.x() * ac.y() - ab.y() * ac.x() < 0) ++flipped;
  }
  return flipped;
}

}  // namespace mq
