#include "core/mesh/longest_edge_bisection.h"

#include <array>
#include <cmath>
#include <queue>
#include <unordered_map>
#include <utility>

#include "core/common/errors.h"

namespace mq {
namespace {

using Edge = std::pair<int, int>;  // (smaller vertex, larger vertex)

Edge make_edge(int a, int b) { return a < b ? Edge(a, b) : Edge(b, a); }

struct EdgeHash {
  size_t operator()(const Edge& e) const {
    return std::hash<long long>()((static_cast<long long>(e.first) << 32) ^ e.second);
  }
};

}  // namespace

TriMesh bisect_longest_edges(const TriMesh& mesh, double max_edge, int max_faces,
                             Refinement* refinement) {
  MQ_CHECK(std::isfinite(max_edge) && max_edge > 0, InvalidInput,
           "bisect_longest_edges: max_edge must be positive and finite, got ", max_edge);
  MQ_CHECK(mesh.V.allFinite(), InvalidInput, "bisect_longest_edges: non-finite vertex position");
  const int nv = mesh.num_vertices();
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(mesh.F(f, k) >= 0 && mesh.F(f, k) < nv, InvalidInput, "bisect_longest_edges: face ",
               f, " has vertex index ", mesh.F(f, k), " out of range");

  std::vector<Vector3d> V(static_cast<size_t>(nv));
  for (int v = 0; v < nv; ++v) V[static_cast<size_t>(v)] = mesh.V.row(v).transpose();
  std::vector<std::array<int, 3>> F(static_cast<size_t>(mesh.num_faces()));
  std::vector<int> parent(F.size());
  std::vector<std::array<Vector3d, 3>> corners(F.size());
  std::unordered_map<Edge, std::vector<int>, EdgeHash> edge_faces;
  for (size_t f = 0; f < F.size(); ++f) {
    const int fi = static_cast<int>(f);
    F[f] = {mesh.F(fi, 0), mesh.F(fi, 1), mesh.F(fi, 2)};
    parent[f] = fi;
    corners[f] = {Vector3d::UnitX(), Vector3d::UnitY(), Vector3d::UnitZ()};
    for (int k = 0; k < 3; ++k) edge_faces[make_edge(F[f][k], F[f][(k + 1) % 3])].push_back(fi);
  }
  // Longest first; among equal lengths the smaller vertex pair, for a deterministic order.
  using Entry = std::pair<double, Edge>;
  auto later = [](const Entry& a, const Entry& b) {
    return a.first != b.first ? a.first < b.first : a.second > b.second;
  };
  std::priority_queue<Entry, std::vector<Entry>, decltype(later)> queue(later);
  auto push = [&](const Edge& e) {
    const double len = (V[static_cast<size_t>(e.first)] - V[static_cast<size_t>(e.second)]).norm();
    if (len > max_edge) queue.emplace(len, e);
  };
  for (const auto& [e, faces] : edge_faces) push(e);

  while (!queue.empty()) {
    const Edge e = queue.top().second;
    queue.pop();
    auto it = edge_faces.find(e);
    if (it == edge_faces.end()) continue;  // already split
    if (F.size() + it->second.size() > static_cast<size_t>(max_faces)) break;
    const std::vector<int> faces = std::move(it->second);
    edge_faces.erase(it);
    const int m = static_cast<int>(V.size());
    V.push_back(0.5 * (V[static_cast<size_t>(e.first)] + V[static_cast<size_t>(e.second)]));
    for (const int f : faces) {
      const auto fs = static_cast<size_t>(f);
      int k = 0;
      while (make_edge(F[fs][k], F[fs][(k + 1) % 3]) != e) ++k;
      const int p = F[fs][k], q = F[fs][(k + 1) % 3], r = F[fs][(k + 2) % 3];
      const Vector3d bp = corners[fs][k], bq = corners[fs][(k + 1) % 3],
                     br = corners[fs][(k + 2) % 3];
      const Vector3d bm = 0.5 * (bp + bq);
      // f becomes (p, m, r); the new face g is (m, q, r).
      const int g = static_cast<int>(F.size());
      F[fs] = {p, m, r};
      corners[fs] = {bp, bm, br};
      F.push_back({m, q, r});
      corners.push_back({bm, bq, br});
      parent.push_back(parent[fs]);
      std::vector<int>& qr = edge_faces[make_edge(q, r)];
      for (int& h : qr)
        if (h == f) h = g;
      edge_faces[make_edge(p, m)].push_back(f);
      edge_faces[make_edge(m, q)].push_back(g);
      std::vector<int>& mr = edge_faces[make_edge(m, r)];
      mr.push_back(f);
      mr.push_back(g);
      push(make_edge(m, r));
    }
    push(make_edge(e.first, m));
    push(make_edge(m, e.second));
  }

  TriMesh out;
  out.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (size_t v = 0; v < V.size(); ++v) out.V.row(static_cast<Eigen::Index>(v)) = V[v].transpose();
  out.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (size_t f = 0; f < F.size(); ++f)
    out.F.row(static_cast<Eigen::Index>(f)) << F[f][0], F[f][1], F[f][2];
  if (refinement) {
    refinement->parent = std::move(parent);
    refinement->corners.resize(static_cast<Eigen::Index>(F.size()), 9);
    for (size_t f = 0; f < F.size(); ++f)
      for (int k = 0; k < 3; ++k)
        refinement->corners.block<1, 3>(static_cast<Eigen::Index>(f), 3 * Eigen::Index{k}) =
            corners[f][static_cast<size_t>(k)].transpose();
  }
  return out;
}

void to_parent(const Refinement& refinement, int& face, Vector3d& b) {
  Vector3d p = Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    p += b(k) * refinement.corners.block<1, 3>(face, 3 * Eigen::Index{k}).transpose();
  b = p;
  face = refinement.parent[static_cast<size_t>(face)];
}

}  // namespace mq
