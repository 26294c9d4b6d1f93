#include "core/mesh/fins.h"

#include <algorithm>
#include <numeric>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"

namespace mq {
namespace {

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::vector<int> fin_faces(const TriMesh& mesh, double min_area_ratio, int* non_manifold_left) {
  const int nf = mesh.num_faces();
  const EdgeTopology topo = edge_topology(mesh.F, mesh.num_vertices());
  if (non_manifold_left) *non_manifold_left = 0;
  bool any = false;
  for (int e = 0; e < topo.num_edges() && !any; ++e) any = topo.is_non_manifold(e);
  if (!any) return {};
  // Pieces: faces joined across edges of two faces.
  std::vector<int> parent(static_cast<size_t>(nf));
  std::iota(parent.begin(), parent.end(), 0);
  for (int e = 0; e < topo.num_edges(); ++e)
    if (topo.edge_faces.degree(e) == 2) {
      const int a = find_root(parent, topo.edge_faces.begin(e)[0]);
      const int b = find_root(parent, topo.edge_faces.begin(e)[1]);
      parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<int> piece(static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f) piece[f] = find_root(parent, f);
  const Eigen::VectorXd area = face_areas(mesh.V, mesh.F);
  std::vector<double> piece_area(static_cast<size_t>(nf), 0.0);
  for (int f = 0; f < nf; ++f) piece_area[piece[f]] += area(f);
  // A piece stays a candidate while every non-manifold edge it meets passes the test.
  // state: 0 meets no non-manifold edge, 1 a fin so far, 2 not a fin.
  std::vector<char> state(static_cast<size_t>(nf), 0);
  std::vector<int> on_edge, pieces;
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (!topo.is_non_manifold(e)) continue;
    on_edge.assign(topo.edge_faces.begin(e), topo.edge_faces.end(e));
    pieces.clear();
    for (const int f : on_edge) pieces.push_back(piece[f]);
    std::sort(pieces.begin(), pieces.end());
    pieces.erase(std::unique(pieces.begin(), pieces.end()), pieces.end());
    for (const int p : pieces) {
      if (state[p] == 2) continue;
      // The faces left on the edge without p: exactly two, of one other, larger piece.
      int left = 0, other = -1;
      bool one_other = true;
      for (const int f : on_edge)
        if (piece[f] != p) {
          ++left;
          if (other >= 0 && piece[f] != other) one_other = false;
          other = piece[f];
        }
      const bool fin =
          left == 2 && one_other && piece_area[other] >= min_area_ratio * piece_area[p];
      state[p] = fin ? 1 : 2;
    }
  }
  std::vector<int> result;
  for (int f = 0; f < nf; ++f)
    if (state[piece[f]] == 1) result.push_back(f);
  if (non_manifold_left)
    for (int e = 0; e < topo.num_edges(); ++e) {
      if (!topo.is_non_manifold(e)) continue;
      int kept = 0;
      for (const int* f = topo.edge_faces.begin(e); f != topo.edge_faces.end(e); ++f)
        kept += state[piece[*f]] != 1;
      *non_manifold_left += kept > 2;
    }
  return result;
}

}  // namespace mq
