#include "core/surface/trivial_connection.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <queue>

#include "core/common/errors.h"

namespace mq {

namespace {

bool interior_edge(const EdgeTopology& topo, int e) { return topo.edge_faces.degree(e) == 2; }

// +1 when a walk crosses e from face f into the other face in the edge's own order (its first
// face to its second), -1 the other way.
int crossing_sign(const EdgeTopology& topo, int e, int from) {
  return topo.edge_faces.begin(e)[0] == from ? 1 : -1;
}

// The dual spanning tree of tree-cotree over the faces, across the interior edges not in the
// primal tree: each face's parent, the edge to it and its depth (roots: -1 and 0).
struct DualTree {
  std::vector<int> parent_edge, parent, depth;
  std::vector<char> in_cotree;  // #E
};

DualTree cotree(const EdgeTopology& topo, const MatrixX3i& TT, const std::vector<char>& in_tree) {
  const int nf = static_cast<int>(TT.rows());
  DualTree d;
  d.parent_edge.assign(static_cast<size_t>(nf), -1);
  d.parent.assign(static_cast<size_t>(nf), -1);
  d.depth.assign(static_cast<size_t>(nf), 0);
  d.in_cotree.assign(static_cast<size_t>(topo.num_edges()), 0);
  std::vector<char> seen(static_cast<size_t>(nf), 0);
  for (int s = 0; s < nf; ++s) {
    if (seen[s]) continue;
    seen[s] = 1;
    std::queue<int> q;
    q.push(s);
    while (!q.empty()) {
      const int f = q.front();
      q.pop();
      for (int k = 0; k < 3; ++k) {
        const int g = TT(f, k), e = topo.FE(f, k);
        if (g < 0 || seen[g] || in_tree[e]) continue;
        seen[g] = 1;
        d.in_cotree[e] = 1;
        d.parent[g] = f;
        d.parent_edge[g] = e;
        d.depth[g] = d.depth[f] + 1;
        q.push(g);
      }
    }
  }
  return d;
}

// The dual loop interior edge e closes: across e from its first face f to g, then back from g
// to f through the dual tree, as (edge, crossing sign); empty when f and g are not joined.
std::vector<std::pair<int, int>> generator_loop(const EdgeTopology& topo, const DualTree& d,
                                                int e) {
  const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
  std::vector<std::pair<int, int>> loop{{e, 1}};  // (edge, crossing sign)
  std::vector<std::pair<int, int>> down;          // f's side, reversed afterwards
  int a = g, b = f;
  while (a != b) {
    if (d.depth[a] >= d.depth[b]) {
      // Up from a to its parent.
      loop.emplace_back(d.parent_edge[a], crossing_sign(topo, d.parent_edge[a], a));
      a = d.parent[a];
    } else {
      // From b's parent down to b (walked later, in order).
      down.emplace_back(d.parent_edge[b], crossing_sign(topo, d.parent_edge[b], d.parent[b]));
      b = d.parent[b];
    }
    if (a < 0 || b < 0) break;  // different dual components: not a loop (cannot happen)
  }
  if (a != b || a < 0) return {};
  loop.insert(loop.end(), down.rbegin(), down.rend());
  return loop;
}

}  // namespace

TrivialConnection::TrivialConnection(const MatrixX3d& V, const MatrixX3i& F,
                                     const EdgeTopology& topo, const MatrixX3i& TT, int N)
    : V_(V), F_(F), topo_(topo), TT_(TT), N_(N) {
  MQ_CHECK(N >= 1 && N <= 4, InvalidInput, "trivial connection: N must be in [1, 4], got ", N);
  MQ_CHECK(TT.rows() == F.rows(), InvalidInput,
           "trivial connection: the face adjacency does not match the faces");
  mark_interior_vertices();
  measure_metric();
  find_components();
  std::vector<Eigen::Triplet<double>> t = vertex_rows();
  const int rows = add_generator_rows(primal_tree(), t);
  factorise(t, rows);
}

// Interior vertices: referenced, every edge manifold, one fan (a bow tie's star is no loop).
void TrivialConnection::mark_interior_vertices() {
  const int nv = static_cast<int>(V_.rows()), nf = static_cast<int>(F_.rows());
  interior_.assign(static_cast<size_t>(nv), 0);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) interior_[F_(f, k)] = 1;
  for (int e = 0; e < topo_.num_edges(); ++e)
    if (!interior_edge(topo_, e)) interior_[topo_.E(e, 0)] = interior_[topo_.E(e, 1)] = 0;
  const std::vector<char> multi = multi_fan_vertices(F_, nv, topo_);
  for (int v = 0; v < nv; ++v)
    if (multi[v]) interior_[v] = 0;
}

// Angle defects, vertex areas, cotangent weights, Levi-Civita transport across edges.
void TrivialConnection::measure_metric() {
  const int nv = static_cast<int>(V_.rows()), nf = static_cast<int>(F_.rows());
  const int ne = topo_.num_edges();
  K_ = Eigen::VectorXd::Zero(nv);
  area_ = Eigen::VectorXd::Zero(nv);
  Eigen::VectorXd angle_sum = Eigen::VectorXd::Zero(nv);
  weight_ = Eigen::VectorXd::Zero(ne);
  for (int f = 0; f < nf; ++f) {
    const Vector3d x[3] = {V_.row(F_(f, 0)), V_.row(F_(f, 1)), V_.row(F_(f, 2))};
    const double twice_area = (x[1] - x[0]).cross(x[2] - x[0]).norm();
    for (int c = 0; c < 3; ++c) {
      const Vector3d a = x[(c + 1) % 3] - x[c], b = x[(c + 2) % 3] - x[c];
      const double s = a.cross(b).norm(), d = a.dot(b);
      angle_sum(F_(f, c)) += std::atan2(s, d);
      area_(F_(f, c)) += twice_area / 6;
      // The angle at corner c faces the edge from corner c+1 to c+2.
      if (s > 0) weight_(topo_.FE(f, (c + 1) % 3)) += 0.5 * d / s;
    }
  }
  // Obtuse pairs give non-positive weights, which would leave the Laplacian indefinite; a
  // small positive floor keeps it definite and changes the metric only on such slivers.
  for (int e = 0; e < ne; ++e)
    weight_(e) = interior_edge(topo_, e) ? std::max(weight_(e), 1e-3) : 0;
  for (int v = 0; v < nv; ++v) K_(v) = interior_[v] ? kTwoPi - angle_sum(v) : 0.0;
  const FaceFrames fr = face_frames(V_, F_);
  transport_ = Eigen::VectorXd::Zero(ne);
  for (int e = 0; e < ne; ++e)
    if (interior_edge(topo_, e)) transport_(e) = transport_angle(V_, topo_, fr, e);
}

// Components (through edges), and which are closed.
void TrivialConnection::find_components() {
  const int nv = static_cast<int>(V_.rows()), nf = static_cast<int>(F_.rows());
  component_.assign(static_cast<size_t>(nv), -1);
  const Adjacency adj = vertex_adjacency(F_, nv);
  int n = 0;
  for (int s = 0; s < nv; ++s) {
    if (component_[s] >= 0) continue;
    component_[s] = n;
    std::vector<int> stack{s};
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (const int* w = adj.begin(v); w != adj.end(v); ++w)
        if (component_[*w] < 0) {
          component_[*w] = n;
          stack.push_back(*w);
        }
    }
    ++n;
  }
  closed_.assign(static_cast<size_t>(n), 1);
  component_vertices_.assign(static_cast<size_t>(n), {});
  std::vector<char> used(static_cast<size_t>(nv), 0);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) used[F_(f, k)] = 1;
  for (int v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    component_vertices_[component_[v]].push_back(v);
    if (!interior_[v]) closed_[component_[v]] = 0;
  }
}

// Vertex rows: every interior vertex but, on a closed component, its last one (the rows of a
// closed component sum to zero; the dropped one is implied); their signed edge incidence.
std::vector<Eigen::Triplet<double>> TrivialConnection::vertex_rows() {
  const int nv = static_cast<int>(V_.rows()), nf = static_cast<int>(F_.rows());
  row_of_vertex_.assign(static_cast<size_t>(nv), -1);
  std::vector<int> last(closed_.size(), -1);
  for (int v = 0; v < nv; ++v)
    if (interior_[v] && closed_[component_[v]]) last[component_[v]] = v;
  for (int v = 0; v < nv; ++v)
    if (interior_[v] && !(closed_[component_[v]] && last[component_[v]] == v))
      row_of_vertex_[v] = vertex_rows_++;
  std::vector<Eigen::Triplet<double>> t;
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      const int v = F_(f, c), row = row_of_vertex_[v];
      if (row < 0) continue;
      // Counter-clockwise around v, the next face lies across the edge from corner c+2 to c.
      const int e = topo_.FE(f, (c + 2) % 3);
      t.emplace_back(row, e, crossing_sign(topo_, e, f));
    }
  return t;
}

// Generators (tree-cotree, Eppstein 2003): a primal spanning tree grown from every
// non-interior vertex of a component at once (its boundary loops contracted to one root), a
// dual spanning tree over the interior edges left, and each interior edge in neither closes
// one dual loop: 2g + b - 1 per component. This is the primal tree.
std::vector<char> TrivialConnection::primal_tree() const {
  const int nv = static_cast<int>(V_.rows()), ne = topo_.num_edges();
  std::vector<char> in_tree(static_cast<size_t>(ne), 0);
  std::vector<std::vector<std::pair<int, int>>> star(static_cast<size_t>(nv));
  for (int e = 0; e < ne; ++e) {
    star[topo_.E(e, 0)].emplace_back(topo_.E(e, 1), e);
    star[topo_.E(e, 1)].emplace_back(topo_.E(e, 0), e);
  }
  std::vector<char> seen(static_cast<size_t>(nv), 0);
  std::queue<int> q;
  for (size_t c = 0; c < component_vertices_.size(); ++c) {
    if (component_vertices_[c].empty()) continue;
    if (closed_[c]) {
      seen[component_vertices_[c][0]] = 1;
      q.push(component_vertices_[c][0]);
    } else {
      for (const int v : component_vertices_[c])
        if (!interior_[v]) {
          seen[v] = 1;
          q.push(v);
        }
    }
  }
  while (!q.empty()) {
    const int v = q.front();
    q.pop();
    for (const auto& [w, e] : star[v]) {
      if (seen[w] || !interior_edge(topo_, e)) continue;
      seen[w] = 1;
      in_tree[e] = 1;
      q.push(w);
    }
  }
  return in_tree;
}

// One row per generator loop (the interior edges in neither tree), with its Levi-Civita
// holonomy.
int TrivialConnection::add_generator_rows(const std::vector<char>& in_tree,
                                          std::vector<Eigen::Triplet<double>>& t) {
  const DualTree dual = cotree(topo_, TT_, in_tree);
  int rows = vertex_rows_;
  for (int e = 0; e < topo_.num_edges(); ++e) {
    if (!interior_edge(topo_, e) || in_tree[e] || dual.in_cotree[e]) continue;
    const std::vector<std::pair<int, int>> loop = generator_loop(topo_, dual, e);
    if (loop.empty()) continue;
    double holonomy = 0;
    for (const auto& [edge, sign] : loop) {
      holonomy += sign * transport_(edge);
      t.emplace_back(rows, edge, sign);
    }
    generator_holonomy_.push_back(holonomy);
    ++rows;
  }
  return rows;
}

// The cotangent Laplacian of the vertex rows and the system augmented by the generators.
void TrivialConnection::factorise(const std::vector<Eigen::Triplet<double>>& t, int rows) {
  const int ne = topo_.num_edges();
  A_.resize(rows, ne);
  A_.setFromTriplets(t.begin(), t.end());
  const Eigen::SparseMatrix<double> W = [&] {
    Eigen::SparseMatrix<double> w(ne, ne);
    std::vector<Eigen::Triplet<double>> d;
    d.reserve(static_cast<size_t>(ne));
    for (int e = 0; e < ne; ++e) d.emplace_back(e, e, weight_(e));
    w.setFromTriplets(d.begin(), d.end());
    return w;
  }();
  const Eigen::SparseMatrix<double> Av = A_.topRows(vertex_rows_);
  const Eigen::SparseMatrix<double> AvT = Av.transpose(), AT = A_.transpose();
  Eigen::SparseMatrix<double> L = Av * W * AvT;
  laplacian_.compute(L);
  MQ_CHECK(laplacian_.info() == Eigen::Success, SolverFailure,
           "trivial connection: the cotangent Laplacian could not be factorised");
  Eigen::SparseMatrix<double> M = A_ * W * AT;
  augmented_.compute(M);
  MQ_CHECK(augmented_.info() == Eigen::Success, SolverFailure,
           "trivial connection: the generator system could not be factorised");
}

int TrivialConnection::unbalanced_component(const std::vector<int>& index) const {
  for (size_t c = 0; c < closed_.size(); ++c) {
    if (!closed_[c] || component_vertices_[c].empty()) continue;
    // Angle defects of a closed surface sum to 2 pi chi (Gauss-Bonnet, exact discretely).
    double k = 0;
    long sum = 0;
    for (const int v : component_vertices_[c]) {
      k += K_(v);
      sum += index[static_cast<size_t>(v)];
    }
    const long chi_n = std::lround(k / kTwoPi * N_);
    if (sum != chi_n) return static_cast<int>(c);
  }
  return -1;
}

Eigen::VectorXd TrivialConnection::solve_poisson(const Eigen::VectorXd& rhs) const {
  const int nv = static_cast<int>(V_.rows());
  MQ_CHECK(rhs.size() == nv, InvalidInput, "trivial connection: ", rhs.size(),
           " right-hand sides for ", nv, " vertices");
  Eigen::VectorXd b(vertex_rows_);
  for (int v = 0; v < nv; ++v)
    if (row_of_vertex_[v] >= 0) b(row_of_vertex_[v]) = rhs(v);
  const Eigen::VectorXd y = laplacian_.solve(b);
  MQ_CHECK(laplacian_.info() == Eigen::Success && y.allFinite(), SolverFailure,
           "trivial connection: the Poisson solve failed");
  Eigen::VectorXd u = Eigen::VectorXd::Zero(nv);
  for (int v = 0; v < nv; ++v)
    if (row_of_vertex_[v] >= 0) u(v) = y(row_of_vertex_[v]);
  // A closed component's u is defined up to a constant: mean zero over its area.
  for (size_t c = 0; c < closed_.size(); ++c) {
    if (!closed_[c] || component_vertices_[c].empty()) continue;
    double s = 0, a = 0;
    for (const int v : component_vertices_[c]) {
      s += area_(v) * u(v);
      a += area_(v);
    }
    if (a > 0)
      for (const int v : component_vertices_[c]) u(v) -= s / a;
  }
  return u;
}

Eigen::VectorXd TrivialConnection::boundary_rotation(const Eigen::VectorXd& boundary) const {
  const int nv = static_cast<int>(V_.rows()), nf = static_cast<int>(F_.rows());
  Eigen::VectorXd y = Eigen::VectorXd::Zero(topo_.num_edges());
  if (boundary.size() == 0) return y;
  MQ_CHECK(boundary.size() == nv && boundary.allFinite(), InvalidInput,
           "trivial connection: ", boundary.size(), " boundary values for ", nv,
           " vertices, or not finite");
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      const int v = F_(f, c);
      if (interior_[v]) continue;
      const int e = topo_.FE(f, (c + 2) % 3);
      y(e) += crossing_sign(topo_, e, f) * boundary(v);
    }
  return weight_.cwiseProduct(y);
}

Eigen::VectorXd TrivialConnection::log_scale(const std::vector<int>& index,
                                             const Eigen::VectorXd& boundary) const {
  const int nv = static_cast<int>(V_.rows());
  MQ_CHECK(static_cast<int>(index.size()) == nv, InvalidInput, "trivial connection: ", index.size(),
           " indices for ", nv, " vertices");
  const int bad = unbalanced_component(index);
  MQ_CHECK(bad < 0, InvalidInput, "trivial connection: the indices of closed component ", bad,
           " do not sum to N times its Euler characteristic");
  // Delta u = K - k with Delta the non-positive cotangent Laplacian; the factorised matrix is
  // -Delta: (-Delta) u = k - K.
  Eigen::VectorXd rhs(nv);
  const double unit = kTwoPi / N_;
  for (int v = 0; v < nv; ++v)
    rhs(v) = interior_[v] ? index[static_cast<size_t>(v)] * unit - K_(v) : 0.0;
  if (boundary.size() == 0) return solve_poisson(rhs);
  // The known boundary values moved to the right-hand side: (-Delta)_II u_I = b - A_I W A_B^T u_B.
  const Eigen::VectorXd coupling = A_.topRows(vertex_rows_) * boundary_rotation(boundary);
  for (int v = 0; v < nv; ++v)
    if (row_of_vertex_[v] >= 0) rhs(v) -= coupling(row_of_vertex_[v]);
  Eigen::VectorXd u = solve_poisson(rhs);
  for (int v = 0; v < nv; ++v)
    if (!interior_[v]) u(v) = boundary(v);
  return u;
}

// Each generator's holonomy is rounded to whole 1/N turns from the flat metric's own (the
// Levi-Civita one plus the rotation of the vertex rows alone, x_v = W A_v^T L^-1 b_v + y, the
// metric's connection): what is left, at most half a turn unit, is the rotation no conformal
// layout follows, spread over the surface as stretch (rounded from the Levi-Civita holonomy alone
// it could be anything: genus 3 at 0.08, 24% of the weave's pieces over aspect 1.6; issue 23).
void TrivialConnection::set_generator_rows(Eigen::VectorXd& b, const Eigen::VectorXd& y) const {
  const Eigen::Index generators = A_.rows() - vertex_rows_;
  if (generators == 0) return;  // a closed sphere-like base: no solve to spend
  const double unit = kTwoPi / N_;
  const Eigen::VectorXd lambda_v = laplacian_.solve(Eigen::VectorXd(b.head(vertex_rows_)));
  MQ_CHECK(laplacian_.info() == Eigen::Success && lambda_v.allFinite(), SolverFailure,
           "trivial connection: the metric's rotation could not be solved");
  const Eigen::VectorXd x_v =
      weight_.cwiseProduct(Eigen::SparseMatrix<double>(A_.topRows(vertex_rows_)).transpose() *
                           lambda_v) +
      y;
  const Eigen::VectorXd flux = A_.bottomRows(generators) * x_v,
                        boundary_flux = A_.bottomRows(generators) * y;
  for (Eigen::Index g = 0; g < generators; ++g) {
    const double h = generator_holonomy_[static_cast<size_t>(g)], flat = h + flux(g);
    b(vertex_rows_ + g) = unit * std::round(flat / unit) - h - boundary_flux(g);
  }
}

ConeMetric TrivialConnection::solve(const std::vector<int>& index, const MatrixX3d& guidance,
                                    const Eigen::VectorXd& boundary) const {
  const int nv = static_cast<int>(V_.rows()), nf = static_cast<int>(F_.rows());
  const int ne = topo_.num_edges();
  MQ_CHECK(guidance.rows() == nf, InvalidInput, "trivial connection: ", guidance.rows(),
           " guidance vectors for ", nf, " faces");
  ConeMetric out;
  out.u = log_scale(index, boundary);
  const double unit = kTwoPi / N_;
  // Minimal rotation (in the cotangent-weighted norm) with the prescribed holonomy around every
  // interior vertex and generator: x = W A^T (A W A^T)^-1 b.
  Eigen::VectorXd b = Eigen::VectorXd::Zero(A_.rows());
  for (int v = 0; v < nv; ++v)
    if (row_of_vertex_[v] >= 0) b(row_of_vertex_[v]) = index[static_cast<size_t>(v)] * unit - K_(v);
  // With boundary values, x = W A^T lambda + y, y their own rotation: A x = b still holds.
  const Eigen::VectorXd y = boundary_rotation(boundary);
  if (boundary.size()) b.head(vertex_rows_) -= A_.topRows(vertex_rows_) * y;
  set_generator_rows(b, y);
  const Eigen::VectorXd lambda = augmented_.solve(b);
  MQ_CHECK(augmented_.info() == Eigen::Success && lambda.allFinite(), SolverFailure,
           "trivial connection: the generator solve failed");
  out.rotation = weight_.cwiseProduct(A_.transpose() * lambda);
  if (boundary.size()) out.rotation += y;

  // The field: parallel along a dual spanning tree for transport + rotation, which by the
  // holonomy constraints makes it parallel across every interior edge up to whole turns.
  const FaceFrames fr = face_frames(V_, F_);
  std::vector<double> theta(static_cast<size_t>(nf), 0.0);
  std::vector<int> root(static_cast<size_t>(nf), -1);
  for (int s = 0; s < nf; ++s) {
    if (root[s] >= 0) continue;
    root[s] = s;
    std::queue<int> q;
    q.push(s);
    std::vector<int> members{s};
    while (!q.empty()) {
      const int f = q.front();
      q.pop();
      for (int k = 0; k < 3; ++k) {
        const int g = TT_(f, k), e = topo_.FE(f, k);
        if (g < 0 || root[g] >= 0) continue;
        root[g] = s;
        theta[g] = theta[f] + crossing_sign(topo_, e, f) * (transport_(e) + out.rotation(e));
        q.push(g);
        members.push_back(g);
      }
    }
    // The whole piece turned towards the guidance: maximise sum A |g| cos(N (theta_g - theta)).
    double re = 0, im = 0;
    for (const int f : members) {
      const Vector3d q3 = guidance.row(f).transpose();
      const double len =
          std::hypot(q3.dot(fr.b1.row(f).transpose()), q3.dot(fr.b2.row(f).transpose()));
      if (!(len > 0)) continue;
      const Vector3d x0 = V_.row(F_(f, 0)), x1 = V_.row(F_(f, 1)), x2 = V_.row(F_(f, 2));
      const double a = 0.5 * (x1 - x0).cross(x2 - x0).norm() * len;
      const double d = N_ * (angle_in_frame(q3, fr, f) - theta[f]);
      re += a * std::cos(d);
      im += a * std::sin(d);
    }
    const double turn = (re != 0 || im != 0) ? std::atan2(im, re) / N_ : 0.0;
    for (const int f : members) theta[f] += turn;
  }
  out.field.N = N_;
  out.field.direction.resize(nf, 3);
  for (int f = 0; f < nf; ++f)
    out.field.direction.row(f) = direction_in_frame(theta[f], fr, f).transpose();
  out.field.matching.assign(static_cast<size_t>(ne), 0);
  for (int e = 0; e < ne; ++e) {
    if (!interior_edge(topo_, e)) continue;
    const int f = topo_.edge_faces.begin(e)[0], g = topo_.edge_faces.begin(e)[1];
    const double raw = theta[g] - theta[f] - transport_(e) - out.rotation(e);
    const long k = std::lround(raw / unit);
    out.field.matching[e] = static_cast<int>(((k % N_) + N_) % N_);
  }
  out.field.index.assign(static_cast<size_t>(nv), 0);
  for (int v = 0; v < nv; ++v)
    if (interior_[v]) out.field.index[v] = index[static_cast<size_t>(v)];
  return out;
}

ConeMetric trivial_connection(const MatrixX3d& V, const MatrixX3i& F, const EdgeTopology& topo,
                              const MatrixX3i& TT, const std::vector<int>& index,
                              const MatrixX3d& guidance, int N) {
  return TrivialConnection(V, F, topo, TT, N).solve(index, guidance);
}

}  // namespace mq
