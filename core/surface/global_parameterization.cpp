#include "core/surface/global_parameterization.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/common/union_find.h"

namespace mq {

namespace {

int corner_of(const MatrixX3i& F, int f, int v) {
  for (int k = 0; k < 3; ++k)
    if (F(f, k) == v) return k;
  return -1;
}

// The edges of a breadth-first dual spanning tree (faces joined across TT).
std::vector<char> dual_spanning_tree(const EdgeTopology& topo, const MatrixX3i& TT) {
  std::vector<char> tree(static_cast<size_t>(topo.num_edges()), 0);
  breadth_first_dual_tree(TT, [&](int f, int k, int) { tree[topo.FE(f, k)] = 1; });
  return tree;
}

// Cut graph: the interior edges outside the dual spanning tree, pruned from their dangling
// ends (boundaries, and non-manifold edges, which TT does not cross, anchor it; so do cones
// whose transition is not the identity), and the half-turn sign of each cut edge.
void cut_graph(const EdgeTopology& topo, const MatrixX3i& TT, const DirectionField& field, int nv,
               GlobalParameterization& gp) {
  const int ne = topo.num_edges();
  gp.cut.assign(static_cast<size_t>(ne), 0);
  gp.sign.assign(static_cast<size_t>(ne), 1);
  const std::vector<char> tree = dual_spanning_tree(topo, TT);
  std::vector<int> degree(static_cast<size_t>(nv), 0);
  std::vector<std::vector<int>> edges_at(static_cast<size_t>(nv));
  for (int e = 0; e < ne; ++e) {
    const int a = topo.E(e, 0), b = topo.E(e, 1);
    if (topo.edge_faces.degree(e) != 2) {
      degree[a] += 2;
      degree[b] += 2;
      continue;
    }
    if (tree[e]) continue;
    gp.cut[e] = 1;
    ++degree[a];
    ++degree[b];
    edges_at[a].push_back(e);
    edges_at[b].push_back(e);
  }
  // Only cones whose transition is not the identity need a cut to end at them.
  auto keeps = [&](int v) { return field.N > 1 && field.index[v] % field.N != 0; };
  std::queue<int> leaves;
  for (int v = 0; v < nv; ++v)
    if (degree[v] == 1 && !keeps(v)) leaves.push(v);
  while (!leaves.empty()) {
    const int v = leaves.front();
    leaves.pop();
    if (degree[v] != 1) continue;
    for (const int e : edges_at[v]) {
      if (!gp.cut[e]) continue;
      gp.cut[e] = 0;
      const int w = topo.E(e, 0) == v ? topo.E(e, 1) : topo.E(e, 0);
      --degree[v];
      --degree[w];
      if (degree[w] == 1 && !keeps(w)) leaves.push(w);
      break;
    }
  }
  for (int e = 0; e < ne; ++e) {
    if (gp.cut[e]) ++gp.num_cut_edges;
    // The half turn of a line field's matching; 0 elsewhere (tree edges by construction,
    // pruned ones because the turns around a regular vertex cancel).
    if (gp.cut[e] && field.N == 2 && field.matching[e] == 1) gp.sign[e] = -1;
  }
}

// Corner groups (wedges): corners of one vertex joined across edges that are not cut. Returns
// the number of wedges.
int group_corners(const MatrixX3i& F, const EdgeTopology& topo, GlobalParameterization& gp) {
  const int nf = static_cast<int>(F.rows());
  UnionFind uf(3 * nf);
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (topo.edge_faces.degree(e) != 2 || gp.cut[e]) continue;
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    for (int side = 0; side < 2; ++side) {
      const int v = topo.E(e, side);
      const int cf = corner_of(F, f, v), cg = corner_of(F, g, v);
      if (cf >= 0 && cg >= 0) uf.unite(3 * f + cf, 3 * g + cg);
    }
  }
  gp.corner_wedge.resize(nf, 3);
  std::vector<int> id(static_cast<size_t>(3 * nf), -1);
  int nw = 0;
  for (int c = 0; c < 3 * nf; ++c) {
    const int r = uf.find(c);
    if (id[r] < 0) id[r] = nw++;
    gp.corner_wedge(c / 3, c % 3) = id[r];
  }
  return nw;
}

// The normal equations over the wedges' (u, v), as triplets and two right-hand sides.
struct WedgeSystem {
  std::vector<Eigen::Triplet<double>> t;
  Eigen::MatrixXd rhs;
};

// Dirichlet energy of (u - s d, v - s n x d) per face.
void add_dirichlet(const MatrixX3d& V, const MatrixX3i& F, const DirectionField& field,
                   const GlobalParameterizationOptions& options, const GlobalParameterization& gp,
                   WedgeSystem& sys) {
  const int nf = static_cast<int>(F.rows());
  for (int f = 0; f < nf; ++f) {
    const Vector3d x[3] = {V.row(F(f, 0)), V.row(F(f, 1)), V.row(F(f, 2))};
    Vector3d n = (x[1] - x[0]).cross(x[2] - x[0]);
    const double two_a = n.norm();
    if (!(two_a > 0)) continue;
    n /= two_a;
    const double area = 0.5 * two_a;
    Vector3d grad[3];
    for (int i = 0; i < 3; ++i) grad[i] = n.cross(x[(i + 2) % 3] - x[(i + 1) % 3]) / two_a;
    const double scale =
        options.target_scale * (options.face_scale.size() == nf ? options.face_scale(f) : 1.0);
    const Vector3d d = scale * field.direction.row(f).transpose();
    const Vector3d d2 = n.cross(d);
    for (int i = 0; i < 3; ++i) {
      const int wi = gp.corner_wedge(f, i);
      for (int j = 0; j < 3; ++j)
        sys.t.emplace_back(wi, gp.corner_wedge(f, j), area * grad[i].dot(grad[j]));
      sys.rhs(wi, 0) += area * grad[i].dot(d);
      sys.rhs(wi, 1) += area * grad[i].dot(d2);
    }
  }
}

// Per cut edge (p, q) between faces f and g: uv_g(p) - uv_g(q) = s (uv_f(p) - uv_f(q)).
void add_cut_constraints(const MatrixX3i& F, const EdgeTopology& topo, double cut_weight,
                         const GlobalParameterization& gp, WedgeSystem& sys) {
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (!gp.cut[e]) continue;
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    const int p = topo.E(e, 0), q = topo.E(e, 1);
    const int w[4] = {
        gp.corner_wedge(g, corner_of(F, g, p)), gp.corner_wedge(g, corner_of(F, g, q)),
        gp.corner_wedge(f, corner_of(F, f, p)), gp.corner_wedge(f, corner_of(F, f, q))};
    const double s = gp.sign[e];
    const double c[4] = {1, -1, -s, s};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) sys.t.emplace_back(w[i], w[j], cut_weight * c[i] * c[j]);
  }
}

// The pinned vertices (their first wedge) at their coordinates.
void add_pins(const MatrixX3i& F, int nv, const GlobalParameterizationOptions& options,
              const GlobalParameterization& gp, WedgeSystem& sys) {
  const int nf = static_cast<int>(F.rows());
  std::vector<int> first_wedge(static_cast<size_t>(nv), -1);
  if (!options.pinned.empty())
    for (int f = nf - 1; f >= 0; --f)
      for (int k = 2; k >= 0; --k) first_wedge[F(f, k)] = gp.corner_wedge(f, k);
  for (const auto& [v, at] : options.pinned) {
    MQ_CHECK(v >= 0 && v < nv, InvalidInput, "global parameterisation: pinned vertex ", v,
             " out of range");
    const int w = first_wedge[v];
    if (w < 0) continue;
    sys.t.emplace_back(w, w, options.pin_weight);
    sys.rhs(w, 0) += options.pin_weight * at.x();
    sys.rhs(w, 1) += options.pin_weight * at.y();
  }
}

// The fixed translations of cut edges: weight (uv_g - s uv_f - t)^2 at both ends.
void add_fixed_translations(const MatrixX3i& F, const EdgeTopology& topo,
                            const GlobalParameterizationOptions& options,
                            const GlobalParameterization& gp, WedgeSystem& sys) {
  for (const auto& [e, tr] : options.fixed_translation) {
    if (e < 0 || e >= topo.num_edges() || !gp.cut[e]) continue;
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    const double s = gp.sign[e];
    for (int side = 0; side < 2; ++side) {
      const int v = topo.E(e, side);
      const int wg = gp.corner_wedge(g, corner_of(F, g, v)),
                wf = gp.corner_wedge(f, corner_of(F, f, v));
      const double wt = options.cut_weight;
      sys.t.emplace_back(wg, wg, wt);
      sys.t.emplace_back(wf, wf, wt);
      sys.t.emplace_back(wg, wf, -s * wt);
      sys.t.emplace_back(wf, wg, -s * wt);
      sys.rhs(wg, 0) += wt * tr.x();
      sys.rhs(wg, 1) += wt * tr.y();
      sys.rhs(wf, 0) -= s * wt * tr.x();
      sys.rhs(wf, 1) -= s * wt * tr.y();
    }
  }
}

// One sparse factorisation, two right-hand sides: the wedges' coordinates.
void solve_wedges(WedgeSystem& sys, int nw, GlobalParameterization& gp) {
  // Translations are free per component: a whisper of regularisation fixes them.
  for (int i = 0; i < nw; ++i) sys.t.emplace_back(i, i, 1e-9);
  Eigen::SparseMatrix<double> M(nw, nw);
  M.setFromTriplets(sys.t.begin(), sys.t.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
  MQ_CHECK(ldlt.info() == Eigen::Success, SolverFailure,
           "global parameterisation: the system could not be factorised");
  const Eigen::MatrixXd uv = ldlt.solve(sys.rhs);
  MQ_CHECK(ldlt.info() == Eigen::Success && uv.allFinite(), SolverFailure,
           "global parameterisation: the solve failed");
  gp.wedge_uv.resize(nw, 2);
  for (int i = 0; i < nw; ++i) gp.wedge_uv.row(i) << uv(i, 0), uv(i, 1);
}

}  // namespace

void GlobalParameterizationOptions::validate() const {
  MQ_CHECK(
      std::isfinite(cut_weight) && cut_weight > 0 && std::isfinite(pin_weight) && pin_weight > 0,
      InvalidInput, "global parameterisation: the cut and pin weights must be positive");
}

GlobalParameterization global_parameterization(const MatrixX3d& V, const MatrixX3i& F,
                                               const EdgeTopology& topo, const MatrixX3i& TT,
                                               const DirectionField& field,
                                               const GlobalParameterizationOptions& options) {
  const int nf = static_cast<int>(F.rows()), nv = static_cast<int>(V.rows());
  MQ_CHECK(field.direction.rows() == nf &&
               static_cast<int>(field.matching.size()) == topo.num_edges() &&
               static_cast<int>(field.index.size()) == nv,
           InvalidInput, "global parameterisation: the field does not match the mesh");
  MQ_CHECK(options.face_scale.size() == 0 || options.face_scale.size() == nf, InvalidInput,
           "global parameterisation: ", options.face_scale.size(), " face scales for ", nf,
           " faces");
  MQ_CHECK(
      field.N == 1 || field.N == 2, InvalidInput,
      "global parameterisation: the field must be a vector or a line field, got N = ", field.N);
  options.validate();
  GlobalParameterization gp;
  gp.field = field;
  gp.singular.assign(static_cast<size_t>(nv), 0);
  for (int v = 0; v < nv; ++v)
    if (field.index[v] != 0) {
      gp.singular[v] = 1;
      ++gp.num_singular;
    }
  cut_graph(topo, TT, field, nv, gp);
  const int nw = group_corners(F, topo, gp);
  WedgeSystem sys;
  sys.rhs = Eigen::MatrixXd::Zero(nw, 2);
  add_dirichlet(V, F, field, options, gp, sys);
  add_cut_constraints(F, topo, options.cut_weight, gp, sys);
  add_pins(F, nv, options, gp, sys);
  add_fixed_translations(F, topo, options, gp, sys);
  solve_wedges(sys, nw, gp);
  return gp;
}

bool unfold_patch(const GlobalParameterization& gp, const EdgeTopology& topo, const MatrixX3i& TT,
                  const MatrixX3d& V, const MatrixX3i& F, const std::vector<int>& faces,
                  const MatrixX3i& vertex_of, int num_local, MatrixX2d& uv, double tolerance) {
  if (faces.empty()) return false;
  std::unordered_map<int, int> local;
  local.reserve(faces.size() * 2);
  for (size_t i = 0; i < faces.size(); ++i) local.emplace(faces[i], static_cast<int>(i));
  // Each face's map into the patch frame: x -> sigma * uv + tau.
  std::vector<double> sigma(faces.size(), 0);
  std::vector<Vector2d> tau(faces.size(), Vector2d::Zero());
  std::vector<char> seen(faces.size(), 0);
  uv.setZero(num_local, 2);
  std::vector<char> set(static_cast<size_t>(num_local), 0);
  std::queue<int> q;
  seen[0] = 1;
  sigma[0] = 1;
  q.push(0);
  while (!q.empty()) {
    const int i = q.front();
    q.pop();
    const int f = faces[static_cast<size_t>(i)];
    for (int c = 0; c < 3; ++c) {
      const int lv = vertex_of(i, c);
      if (!set[lv]) {
        uv.row(lv) = (sigma[i] * gp.uv(f, c) + tau[i]).transpose();
        set[lv] = 1;
      }
    }
    for (int k = 0; k < 3; ++k) {
      const int g = TT(f, k);
      if (g < 0) continue;
      auto it = local.find(g);
      if (it == local.end() || seen[it->second]) continue;
      const int j = it->second;
      const int e = topo.FE(f, k);
      if (!gp.cut[e]) {
        sigma[j] = sigma[i];
        tau[j] = tau[i];
      } else {
        // uv_g = s uv_f + t across the cut, so uv_f = s (uv_g - t).
        const double s = gp.sign[e];
        Vector2d tr = Vector2d::Zero();
        for (int side = 0; side < 2; ++side) {
          const int v = topo.E(e, side);
          tr += gp.uv(g, corner_of(F, g, v)) - s * gp.uv(f, corner_of(F, f, v));
        }
        tr *= 0.5;
        sigma[j] = sigma[i] * s;
        tau[j] = tau[i] - sigma[i] * s * tr;
      }
      seen[j] = 1;
      q.push(j);
    }
  }
  for (size_t i = 0; i < faces.size(); ++i) {
    if (!seen[i]) return false;
    const int f = faces[i];
    double edge = 0;
    for (int c = 0; c < 3; ++c)
      edge = std::max(edge, (V.row(F(f, c)) - V.row(F(f, (c + 1) % 3))).norm());
    for (int c = 0; c < 3; ++c) {
      const Vector2d mine = sigma[i] * gp.uv(f, c) + tau[i];
      if ((mine - uv.row(vertex_of(static_cast<Eigen::Index>(i), c)).transpose()).norm() >
          tolerance * edge)
        return false;
    }
  }
  return true;
}

bool locate_in_charts(const GlobalParameterization& gp, const EdgeTopology& topo,
                      const MatrixX3i& TT, const MatrixX3i& F, int& face, Vector2d& x,
                      Vector3d& barycentric, int max_steps, ChartTransform* transform) {
  int previous = -1;
  for (int step = 0; step < max_steps; ++step) {
    const Vector2d a = gp.uv(face, 0), b = gp.uv(face, 1), c = gp.uv(face, 2);
    const Vector2d e0 = b - a, e1 = c - a, d = x - a;
    const double den = e0.x() * e1.y() - e1.x() * e0.y();
    if (!(std::abs(den) > 0)) return false;
    const double v = (d.x() * e1.y() - e1.x() * d.y()) / den;
    const double w = (e0.x() * d.y() - d.x() * e0.y()) / den;
    barycentric = Vector3d(1 - v - w, v, w);
    // Inside, up to rounding: done.
    const double eps = 1e-9;
    if (barycentric.minCoeff() >= -eps) {
      barycentric = barycentric.cwiseMax(0.0);
      barycentric /= barycentric.sum();
      return true;
    }
    // Cross the edge opposite the most negative weight (corner k: edge k+1 -> k+2), never
    // straight back to the face just left (a flipped face could bounce the walk).
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int i, int j) { return barycentric(i) < barycentric(j); });
    int next = -1, edge_slot = -1;
    for (const int k : order) {
      if (barycentric(k) >= -eps) break;
      const int slot = (k + 1) % 3;
      const int g = TT(face, slot);
      if (g < 0 || g == previous) continue;
      next = g;
      edge_slot = slot;
      break;
    }
    if (next < 0) return false;
    const int e = topo.FE(face, edge_slot);
    if (gp.cut[e]) {
      const double s = gp.sign[e];
      Vector2d t = Vector2d::Zero();
      for (int side = 0; side < 2; ++side) {
        const int v = topo.E(e, side);
        t += gp.uv(next, corner_of(F, next, v)) - s * gp.uv(face, corner_of(F, face, v));
      }
      x = s * x + 0.5 * t;
      if (transform) {
        transform->sigma *= s;
        transform->tau = s * transform->tau + 0.5 * t;
      }
    }
    previous = face;
    face = next;
  }
  return false;
}

std::vector<CutPath> cut_paths(const GlobalParameterization& gp, const EdgeTopology& topo,
                               const MatrixX3i& F_) {
  const int ne = topo.num_edges();
  const int nv = static_cast<int>(gp.singular.size());
  std::vector<int> degree(static_cast<size_t>(nv), 0);
  std::vector<char> boundary(static_cast<size_t>(nv), 0);
  std::vector<std::vector<int>> at(static_cast<size_t>(nv));
  for (int e = 0; e < ne; ++e) {
    const int a = topo.E(e, 0), b = topo.E(e, 1);
    if (topo.edge_faces.degree(e) != 2) boundary[a] = boundary[b] = 1;
    if (!gp.cut[e]) continue;
    ++degree[a];
    ++degree[b];
    at[a].push_back(e);
    at[b].push_back(e);
  }
  auto node = [&](int v) { return degree[v] != 2 || gp.singular[v] || boundary[v]; };
  std::vector<char> used(static_cast<size_t>(ne), 0);
  std::vector<CutPath> paths;
  // The wedge of face f at vertex v.
  auto wedge_at = [&](int f, int v) {
    for (int k = 0; k < 3; ++k)
      if (F_(f, k) == v) return gp.corner_wedge(f, k);
    return -1;
  };
  auto walk = [&](int e0, int from) {
    CutPath p;
    p.sign = gp.sign[e0];
    int e = e0, v = from;
    bool flip = false;
    for (;;) {
      used[e] = 1;
      p.edges.push_back(e);
      p.flipped.push_back(flip);
      const int w = topo.E(e, 0) == v ? topo.E(e, 1) : topo.E(e, 0);
      if (node(w)) break;
      int next = -1;
      for (const int f : at[w])
        if (!used[f]) next = f;
      if (next < 0) break;
      // The next edge keeps the orientation if its first face shares the wedge at w with the
      // side this edge's first face is on.
      const int side_a = flip ? topo.edge_faces.begin(e)[1] : topo.edge_faces.begin(e)[0];
      flip = wedge_at(topo.edge_faces.begin(next)[0], w) != wedge_at(side_a, w);
      e = next;
      v = w;
    }
    paths.push_back(std::move(p));
  };
  for (int v = 0; v < nv; ++v)
    if (node(v))
      for (const int e : at[v])
        if (!used[e]) walk(e, v);
  // Closed loops through regular vertices only (a handle's cut).
  for (int e = 0; e < ne; ++e)
    if (gp.cut[e] && !used[e]) walk(e, topo.E(e, 0));
  return paths;
}

Vector2d path_translation(const GlobalParameterization& gp, const EdgeTopology& topo,
                          const MatrixX3i& F, const CutPath& path) {
  Vector2d sum = Vector2d::Zero();
  int n = 0;
  for (size_t k = 0; k < path.edges.size(); ++k) {
    const int e = path.edges[k];
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    const double s = gp.sign[e];
    Vector2d te = Vector2d::Zero();
    for (int side = 0; side < 2; ++side) {
      const int v = topo.E(e, side);
      te += 0.5 * (gp.uv(g, corner_of(F, g, v)) - s * gp.uv(f, corner_of(F, f, v)));
    }
    // An edge the other way round carries the inverse transition: -t for a translation, the
    // same t for a half turn (an involution).
    sum += edge_translation(path, k, te);
    ++n;
  }
  return n > 0 ? Vector2d(sum / n) : Vector2d::Zero();
}

Vector2d edge_translation(const CutPath& path, size_t k, const Vector2d& t) {
  return path.flipped[k] && path.sign > 0 ? Vector2d(-t) : t;
}

}  // namespace mq
