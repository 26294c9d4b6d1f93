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

// The mesh being refined: positions, faces with their parent and corner coordinates in it,
// the faces of each edge, and the edges over max_edge, longest first.
class Bisection {
 public:
  Bisection(const TriMesh& mesh, double max_edge) : max_edge_(max_edge) {
    const int nv = mesh.num_vertices();
    V_.resize(static_cast<size_t>(nv));
    for (int v = 0; v < nv; ++v) V_[static_cast<size_t>(v)] = mesh.V.row(v).transpose();
    F_.resize(static_cast<size_t>(mesh.num_faces()));
    parent_.resize(F_.size());
    corners_.resize(F_.size());
    for (size_t f = 0; f < F_.size(); ++f) {
      const int fi = static_cast<int>(f);
      F_[f] = {mesh.F(fi, 0), mesh.F(fi, 1), mesh.F(fi, 2)};
      parent_[f] = fi;
      corners_[f] = {Vector3d::UnitX(), Vector3d::UnitY(), Vector3d::UnitZ()};
      for (int k = 0; k < 3; ++k)
        edge_faces_[make_edge(F_[f][k], F_[f][(k + 1) % 3])].push_back(fi);
    }
    for (const auto& [e, faces] : edge_faces_) push(e);
  }

  // Splits the longest edges while the faces stay within max_faces.
  void run(int max_faces) {
    while (!queue_.empty()) {
      const Edge e = queue_.top().second;
      queue_.pop();
      auto it = edge_faces_.find(e);
      if (it == edge_faces_.end()) continue;  // already split
      if (F_.size() + it->second.size() > static_cast<size_t>(max_faces)) break;
      const std::vector<int> faces = std::move(it->second);
      edge_faces_.erase(it);
      split(e, faces);
    }
  }

  TriMesh result(Refinement* refinement) {
    TriMesh out;
    out.V.resize(static_cast<Eigen::Index>(V_.size()), 3);
    for (size_t v = 0; v < V_.size(); ++v)
      out.V.row(static_cast<Eigen::Index>(v)) = V_[v].transpose();
    out.F.resize(static_cast<Eigen::Index>(F_.size()), 3);
    for (size_t f = 0; f < F_.size(); ++f)
      out.F.row(static_cast<Eigen::Index>(f)) << F_[f][0], F_[f][1], F_[f][2];
    if (refinement) {
      refinement->parent = std::move(parent_);
      refinement->corners.resize(static_cast<Eigen::Index>(F_.size()), 9);
      for (size_t f = 0; f < F_.size(); ++f)
        for (int k = 0; k < 3; ++k)
          refinement->corners.block<1, 3>(static_cast<Eigen::Index>(f), 3 * Eigen::Index{k}) =
              corners_[f][static_cast<size_t>(k)].transpose();
    }
    return out;
  }

 private:
  using Entry = std::pair<double, Edge>;
  // Longest first; among equal lengths the smaller vertex pair, for a deterministic order.
  struct Later {
    bool operator()(const Entry& a, const Entry& b) const {
      return a.first != b.first ? a.first < b.first : a.second > b.second;
    }
  };

  void push(const Edge& e) {
    const double len =
        (V_[static_cast<size_t>(e.first)] - V_[static_cast<size_t>(e.second)]).norm();
    if (len > max_edge_) queue_.emplace(len, e);
  }

  // Edge e at its midpoint m: each face (p, q, r) across it becomes (p, m, r) and a new face
  // (m, q, r) of the same parent.
  void split(const Edge& e, const std::vector<int>& faces) {
    const int m = static_cast<int>(V_.size());
    V_.push_back(0.5 * (V_[static_cast<size_t>(e.first)] + V_[static_cast<size_t>(e.second)]));
    for (const int f : faces) {
      const auto fs = static_cast<size_t>(f);
      int k = 0;
      while (make_edge(F_[fs][k], F_[fs][(k + 1) % 3]) != e) ++k;
      const int p = F_[fs][k], q = F_[fs][(k + 1) % 3], r = F_[fs][(k + 2) % 3];
      const Vector3d bp = corners_[fs][k], bq = corners_[fs][(k + 1) % 3],
                     br = corners_[fs][(k + 2) % 3];
      const Vector3d bm = 0.5 * (bp + bq);
      const int g = static_cast<int>(F_.size());
      F_[fs] = {p, m, r};
      corners_[fs] = {bp, bm, br};
      F_.push_back({m, q, r});
      corners_.push_back({bm, bq, br});
      parent_.push_back(parent_[fs]);
      std::vector<int>& qr = edge_faces_[make_edge(q, r)];
      for (int& h : qr)
        if (h == f) h = g;
      edge_faces_[make_edge(p, m)].push_back(f);
      edge_faces_[make_edge(m, q)].push_back(g);
      std::vector<int>& mr = edge_faces_[make_edge(m, r)];
      mr.push_back(f);
      mr.push_back(g);
      push(make_edge(m, r));
    }
    push(make_edge(e.first, m));
    push(make_edge(m, e.second));
  }

  const double max_edge_;
  std::vector<Vector3d> V_;
  std::vector<std::array<int, 3>> F_;
  std::vector<int> parent_;
  std::vector<std::array<Vector3d, 3>> corners_;
  std::unordered_map<Edge, std::vector<int>, EdgeHash> edge_faces_;
  std::priority_queue<Entry, std::vector<Entry>, Later> queue_;
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
  Bisection bisection(mesh, max_edge);
  bisection.run(max_faces);
  return bisection.result(refinement);
}

void to_parent(const Refinement& refinement, int& face, Vector3d& b) {
  Vector3d p = Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    p += b(k) * refinement.corners.block<1, 3>(face, 3 * Eigen::Index{k}).transpose();
  b = p;
  face = refinement.parent[static_cast<size_t>(face)];
}

}  // namespace mq
