#include "core/mesh/mesh_topology.h"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>

#include "core/common/errors.h"
#include "core/common/union_find.h"
#include "core/mesh/element_kinds.h"

namespace mq {

namespace {

// Adjacency lists from (from, to) pairs with from in [0, n): each list ascending, duplicates
// removed when unique. A counting sort on `from` then a sort of each (short) list: the same
// result as sorting the pairs, in about linear time.
Adjacency build_adjacency(int n, const std::vector<std::pair<int, int>>& pairs, bool unique) {
  Adjacency adj;
  adj.offsets.assign(static_cast<size_t>(n) + 1, 0);
  for (const auto& [a, b] : pairs) ++adj.offsets[static_cast<size_t>(a) + 1];
  for (int i = 0; i < n; ++i) adj.offsets[i + 1] += adj.offsets[i];
  adj.indices.resize(pairs.size());
  {
    std::vector<int> cursor(adj.offsets.begin(), adj.offsets.end() - 1);
    for (const auto& [a, b] : pairs) adj.indices[cursor[a]++] = b;
  }
  int write = 0;
  for (int i = 0; i < n; ++i) {
    const auto first = adj.indices.begin() + adj.offsets[i];
    auto last = adj.indices.begin() + adj.offsets[i + 1];
    std::sort(first, last);
    if (unique) last = std::unique(first, last);
    adj.offsets[i] = write;
    write =
        static_cast<int>(std::copy(first, last, adj.indices.begin() + write) - adj.indices.begin());
  }
  adj.offsets[n] = write;
  adj.indices.resize(static_cast<size_t>(write));
  return adj;
}

void check_indices(const MatrixX3i& F, int num_vertices) {
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(F(f, k) >= 0 && F(f, k) < num_vertices, InvalidInput, "face ", f,
               " references vertex ", F(f, k), " but the mesh has ", num_vertices, " vertices");
}

}  // namespace

EdgeTopology edge_topology(const MatrixX3i& F, int num_vertices) {
  check_indices(F, num_vertices);
  const int nf = static_cast<int>(F.rows());
  // Half-edges grouped by their smaller vertex (counting sort, ids ascending within a group),
  // then each short group ordered by the larger vertex: the (min vertex, max vertex, id) order
  // that puts copies of an edge next to each other, without a global sort.
  std::vector<int> start(static_cast<size_t>(num_vertices) + 1, 0);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++start[std::min(F(f, k), F(f, (k + 1) % 3)) + 1];
  for (int v = 0; v < num_vertices; ++v) start[v + 1] += start[v];
  std::vector<std::array<int, 3>> half(3 * static_cast<size_t>(nf));
  {
    std::vector<int> cursor(start.begin(), start.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = F(f, k), b = F(f, (k + 1) % 3);
        half[cursor[std::min(a, b)]++] = {std::min(a, b), std::max(a, b), 3 * f + k};
      }
  }
  for (int v = 0; v < num_vertices; ++v)  // stable insertion sort: groups hold a few entries
    for (int i = start[v] + 1; i < start[v + 1]; ++i) {
      const std::array<int, 3> h = half[i];
      int j = i;
      for (; j > start[v] && half[j - 1][1] > h[1]; --j) half[j] = half[j - 1];
      half[j] = h;
    }
  EdgeTopology topo;
  topo.FE.resize(nf, 3);
  std::vector<std::pair<int, int>> edge_face;
  edge_face.reserve(half.size());
  std::vector<std::array<int, 2>> edges;
  for (size_t i = 0; i < half.size(); ++i) {
    if (i == 0 || half[i][0] != half[i - 1][0] || half[i][1] != half[i - 1][1])
      edges.push_back({half[i][0], half[i][1]});
    const int e = static_cast<int>(edges.size()) - 1;
    topo.FE(half[i][2] / 3, half[i][2] % 3) = e;
    edge_face.emplace_back(e, half[i][2] / 3);
  }
  topo.E.resize(static_cast<Eigen::Index>(edges.size()), 2);
  for (size_t e = 0; e < edges.size(); ++e) {
    topo.E(e, 0) = edges[e][0];
    topo.E(e, 1) = edges[e][1];
  }
  topo.edge_faces = build_adjacency(static_cast<int>(edges.size()), edge_face, false);
  return topo;
}

Adjacency vertex_adjacency(const MatrixX3i& F, int num_vertices) {
  check_indices(F, num_vertices);
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(6 * static_cast<size_t>(F.rows()));
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (a == b) continue;
      pairs.emplace_back(a, b);
      pairs.emplace_back(b, a);
    }
  return build_adjacency(num_vertices, pairs, true);
}

Adjacency vertex_faces(const MatrixX3i& F, int num_vertices) {
  check_indices(F, num_vertices);
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(3 * static_cast<size_t>(F.rows()));
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) pairs.emplace_back(F(f, k), f);
  return build_adjacency(num_vertices, pairs, true);
}

MatrixX3i face_adjacency(const EdgeTopology& topo) {
  MatrixX3i TT(topo.FE.rows(), 3);
  for (int f = 0; f < topo.FE.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int e = topo.FE(f, k);
      TT(f, k) = -1;
      if (topo.edge_faces.degree(e) != 2) continue;
      const int* fs = topo.edge_faces.begin(e);
      TT(f, k) = fs[0] == f ? fs[1] : fs[0];
    }
  return TT;
}

int connected_components(const MatrixX3i& F, int num_vertices, std::vector<int>& face_component) {
  check_indices(F, num_vertices);
  UnionFind uf(num_vertices);
  for (int f = 0; f < F.rows(); ++f) {
    uf.unite(F(f, 0), F(f, 1));
    uf.unite(F(f, 0), F(f, 2));
  }
  std::vector<int> root_id(num_vertices, -1);
  face_component.assign(F.rows(), -1);
  int count = 0;
  for (int f = 0; f < F.rows(); ++f) {
    const int r = uf.find(F(f, 0));
    if (root_id[r] < 0) root_id[r] = count++;
    face_component[f] = root_id[r];
  }
  return count;
}

std::vector<std::vector<int>> component_faces(const std::vector<int>& face_component,
                                              int num_components) {
  std::vector<std::vector<int>> groups(num_components);
  for (size_t f = 0; f < face_component.size(); ++f)
    groups[face_component[f]].push_back(static_cast<int>(f));
  return groups;
}

TriMesh extract_faces(const TriMesh& mesh, const std::vector<int>& faces,
                      std::vector<int>* vertex_map) {
  std::vector<int> old_index;
  TriMesh out;
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  const size_t corners = 3 * faces.size();
  // The vertices' index range: one element of an output (its vertices consecutive) spans about
  // a sixth of its corners.
  int lo = std::numeric_limits<int>::max(), hi = -1;
  for (const int f : faces)
    for (int k = 0; k < 3; ++k) {
      lo = std::min(lo, mesh.F(f, k));
      hi = std::max(hi, mesh.F(f, k));
    }
  const size_t span = hi < lo ? 0 : static_cast<size_t>(hi - lo) + 1;
  if (8 * corners >= span) {
    // A large share of the range: a table over it (numbered by first use, as below).
    std::vector<int> new_index(span, -1);
    for (size_t i = 0; i < faces.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const int v = mesh.F(faces[i], k);
        int& id = new_index[static_cast<size_t>(v - lo)];
        if (id < 0) {
          id = static_cast<int>(old_index.size());
          old_index.push_back(v);
        }
        out.F(static_cast<Eigen::Index>(i), k) = id;
      }
  } else {
    // A small part scattered over the mesh: the corners sorted by vertex, so the cost follows
    // the part and not the mesh (a table over the whole mesh per element made placing and
    // measuring every element of a layer quadratic). Same numbering: by first use.
    std::vector<std::pair<int, int>> use(corners);  // (vertex, corner)
    for (size_t i = 0; i < faces.size(); ++i)
      for (int k = 0; k < 3; ++k)
        use[3 * i + static_cast<size_t>(k)] = {mesh.F(faces[i], k), static_cast<int>(3 * i) + k};
    std::sort(use.begin(), use.end());
    std::vector<std::pair<int, int>> first_use;  // (first corner, run start in use)
    for (size_t r = 0; r < use.size(); ++r)
      if (r == 0 || use[r].first != use[r - 1].first)
        first_use.emplace_back(use[r].second, static_cast<int>(r));
    std::sort(first_use.begin(), first_use.end());
    old_index.resize(first_use.size());
    for (size_t j = 0; j < first_use.size(); ++j) {
      const int v = use[static_cast<size_t>(first_use[j].second)].first;
      old_index[j] = v;
      for (size_t r = static_cast<size_t>(first_use[j].second); r < use.size() && use[r].first == v;
           ++r)
        out.F(use[r].second / 3, use[r].second % 3) = static_cast<int>(j);
    }
  }
  out.V.resize(static_cast<Eigen::Index>(old_index.size()), 3);
  for (size_t i = 0; i < old_index.size(); ++i) out.V.row(i) = mesh.V.row(old_index[i]);
  if (mesh.N.rows() == mesh.V.rows() && mesh.N.rows() > 0) {
    out.N.resize(out.V.rows(), 3);
    for (size_t i = 0; i < old_index.size(); ++i) out.N.row(i) = mesh.N.row(old_index[i]);
  }
  if (has_kinds(mesh)) {
    out.kinds = mesh.kinds;
    out.face_kind.resize(faces.size());
    for (size_t i = 0; i < faces.size(); ++i)
      out.face_kind[i] = mesh.face_kind[static_cast<size_t>(faces[i])];
  }
  if (vertex_map) *vertex_map = std::move(old_index);
  return out;
}

void append_mesh(TriMesh& a, const TriMesh& b) {
  const bool normals =
      a.N.rows() == a.V.rows() && b.N.rows() == b.V.rows() && (a.V.rows() > 0 || b.V.rows() > 0);
  const Eigen::Index nv = a.V.rows(), nf = a.F.rows();
  a.V.conservativeResize(nv + b.V.rows(), 3);
  a.V.bottomRows(b.V.rows()) = b.V;
  // Kinds are merged by name; a mesh without kinds contributes kDefaultKind faces.
  const bool kinds_a = has_kinds(a), kinds_b = has_kinds(b);
  if (kinds_a || kinds_b) {
    if (!kinds_a) set_single_kind(a, kDefaultKind);
    std::vector<int> map(b.kinds.size());
    for (size_t k = 0; k < b.kinds.size(); ++k) map[k] = kind_index(a.kinds, b.kinds[k]);
    const int plain = kinds_b ? 0 : kind_index(a.kinds, kDefaultKind);
    for (Eigen::Index f = 0; f < b.F.rows(); ++f)
      a.face_kind.push_back(kinds_b ? map[static_cast<size_t>(b.face_kind[f])] : plain);
  }
  a.F.conservativeResize(nf + b.F.rows(), 3);
  a.F.bottomRows(b.F.rows()) = b.F.array() + static_cast<int>(nv);
  if (nf == 0) remove_unused_kinds(a);  // the kDefaultKind an empty a was given
  if (normals) {
    a.N.conservativeResize(nv + b.N.rows(), 3);
    a.N.bottomRows(b.N.rows()) = b.N;
  } else {
    a.N.resize(0, 3);
  }
}

void remove_unreferenced_vertices(TriMesh& mesh) {
  std::vector<int> new_index(mesh.V.rows(), -1);
  int count = 0;
  std::vector<int> used(mesh.V.rows(), 0);
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[mesh.F(f, k)] = 1;
  for (size_t v = 0; v < used.size(); ++v) new_index[v] = used[v] ? count++ : -1;
  MatrixX3d V(count, 3);
  MatrixX3d N(mesh.N.rows() == mesh.V.rows() ? count : 0, 3);
  for (int v = 0; v < mesh.V.rows(); ++v) {
    if (new_index[v] < 0) continue;
    V.row(new_index[v]) = mesh.V.row(v);
    if (N.rows()) N.row(new_index[v]) = mesh.N.row(v);
  }
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) mesh.F(f, k) = new_index[mesh.F(f, k)];
  mesh.V = std::move(V);
  mesh.N = std::move(N);
}

std::vector<char> multi_fan_vertices(const MatrixX3i& F, int num_vertices,
                                     const EdgeTopology& topo) {
  // Each fan is walked across the manifold edges at the vertex (TT is -1 across the others).
  const Adjacency vf = vertex_faces(F, num_vertices);
  const MatrixX3i TT = face_adjacency(topo);
  std::vector<char> multi(static_cast<size_t>(num_vertices), 0);
  std::vector<int> mark(static_cast<size_t>(F.rows()), -1);
  std::vector<int> stack;
  for (int v = 0; v < num_vertices; ++v) {
    int fans = 0;
    for (const int* it = vf.begin(v); it != vf.end(v); ++it) {
      if (mark[*it] == v) continue;
      ++fans;
      stack.assign(1, *it);
      mark[*it] = v;
      while (!stack.empty()) {
        const int f = stack.back();
        stack.pop_back();
        for (int k = 0; k < 3; ++k) {
          const int g = TT(f, k);
          if (g < 0 || mark[g] == v) continue;
          if (F(f, k) != v && F(f, (k + 1) % 3) != v) continue;
          mark[g] = v;
          stack.push_back(g);
        }
      }
    }
    multi[static_cast<size_t>(v)] = fans > 1;
  }
  return multi;
}

TopologyReport topology_report(const TriMesh& mesh) {
  TopologyReport r;
  const int nv = mesh.num_vertices();
  const EdgeTopology topo = edge_topology(mesh.F, nv);
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (topo.is_boundary(e)) ++r.num_boundary_edges;
    if (topo.is_non_manifold(e)) ++r.num_non_manifold_edges;
  }
  std::vector<int> fc;
  r.num_components = connected_components(mesh.F, nv, fc);
  for (int f = 0; f < mesh.F.rows(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const bool repeated = a == b || b == c || a == c;
    const Vector3d n = (mesh.V.row(b) - mesh.V.row(a)).cross(mesh.V.row(c) - mesh.V.row(a));
    if (repeated || n.squaredNorm() == 0.0) ++r.num_degenerate_faces;
  }
  for (const char multi : multi_fan_vertices(mesh.F, nv, topo))
    r.num_non_manifold_vertices += multi;
  return r;
}

}  // namespace mq
