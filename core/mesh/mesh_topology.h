// Combinatorial structure of a triangle mesh: edges, adjacency, boundaries, components.
#pragma once

#include <queue>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// Compressed adjacency lists: the neighbours of item i are indices[offsets[i] .. offsets[i+1]).
struct Adjacency {
  std::vector<int> offsets;  // size n + 1
  std::vector<int> indices;

  int size() const { return static_cast<int>(offsets.size()) - 1; }
  int degree(int i) const { return offsets[i + 1] - offsets[i]; }
  const int* begin(int i) const { return indices.data() + offsets[i]; }
  const int* end(int i) const { return indices.data() + offsets[i + 1]; }
};

// Undirected edges of a face set and how faces use them.
struct EdgeTopology {
  Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor> E;  // #E by 2, E(e,0) < E(e,1)
  MatrixX3i FE;          // #F by 3: FE(f,k) is the edge from F(f,k) to F(f,(k+1)%3)
  Adjacency edge_faces;  // for each edge, the faces using it (ascending)

  int num_edges() const { return static_cast<int>(E.rows()); }
  bool is_boundary(int e) const { return edge_faces.degree(e) == 1; }
  bool is_non_manifold(int e) const { return edge_faces.degree(e) > 2; }
};

// Builds the edge topology of F. Preconditions: indices of F lie in [0, num_vertices).
// O(#F log #F). Throws InvalidInput for an out-of-range index.
EdgeTopology edge_topology(const MatrixX3i& F, int num_vertices);

// 1-ring vertex neighbours (ascending, without duplicates) of each of num_vertices vertices.
Adjacency vertex_adjacency(const MatrixX3i& F, int num_vertices);

// Faces incident to each vertex (ascending).
Adjacency vertex_faces(const MatrixX3i& F, int num_vertices);

// Face neighbours across each edge: #F by 3, TT(f,k) across the edge F(f,k)-F(f,(k+1)%3);
// -1 across a boundary or a non-manifold edge.
MatrixX3i face_adjacency(const EdgeTopology& topo);

// Breadth first over each component's faces (from its lowest face) joined across TT (the
// manifold edges): calls visit(f, k, g) once per edge of the dual spanning tree this makes, from
// face f across its edge k to a face g not reached before, in the order faces are reached. The
// one walk behind the global layout's cut graph and the line field's representatives.
//   TT  #F by 3, as face_adjacency gives
template <class Visit>
void breadth_first_dual_tree(const MatrixX3i& TT, Visit&& visit) {
  const int nf = static_cast<int>(TT.rows());
  std::vector<char> seen(static_cast<size_t>(nf), 0);
  std::queue<int> q;
  for (int start = 0; start < nf; ++start) {
    if (seen[static_cast<size_t>(start)]) continue;
    seen[static_cast<size_t>(start)] = 1;
    q.push(start);
    while (!q.empty()) {
      const int f = q.front();
      q.pop();
      for (int k = 0; k < 3; ++k) {
        const int g = TT(f, k);
        if (g < 0 || seen[static_cast<size_t>(g)]) continue;
        seen[static_cast<size_t>(g)] = 1;
        visit(f, k, g);
        q.push(g);
      }
    }
  }
}

// Per vertex (#V entries), whether its incident faces, linked through the manifold edges they
// share at it, form more than one fan: a vertex where pieces of surface touch (a bow tie), or
// on a non-manifold edge. 0 for a vertex no face uses.
std::vector<char> multi_fan_vertices(const MatrixX3i& F, int num_vertices,
                                     const EdgeTopology& topo);

// Per-face component id of the vertex-connected pieces (the paper's geometry elements), in
// order of each component's first face; returns the number of components.
//   face_component  output, #F
int connected_components(const MatrixX3i& F, int num_vertices, std::vector<int>& face_component);

// Faces grouped by component: result[c] lists the faces of component c, ascending.
std::vector<std::vector<int>> component_faces(const std::vector<int>& face_component,
                                              int num_components);

// The sub-mesh made of the given faces, with vertices renumbered in order of first use.
//   vertex_map  optional output: for each sub-mesh vertex, its index in mesh
TriMesh extract_faces(const TriMesh& mesh, const std::vector<int>& faces,
                      std::vector<int>* vertex_map = nullptr);

// Appends b to a (vertex indices of b shifted); normals are kept only if both have them.
void append_mesh(TriMesh& a, const TriMesh& b);

// Removes vertices used by no face, renumbering F (and N if present).
void remove_unreferenced_vertices(TriMesh& mesh);

// Summary of topological health.
struct TopologyReport {
  int num_components = 0;
  int num_boundary_edges = 0;
  int num_non_manifold_edges = 0;
  int num_non_manifold_vertices = 0;  // a vertex whose incident faces form more than one fan
  int num_degenerate_faces = 0;       // repeated vertex index or zero area
  bool closed() const { return num_boundary_edges == 0 && num_non_manifold_edges == 0; }
  bool manifold() const { return num_non_manifold_edges == 0 && num_non_manifold_vertices == 0; }
};

// Counts boundary/non-manifold edges, non-manifold vertices, degenerate faces, components.
TopologyReport topology_report(const TriMesh& mesh);

}  // namespace mq
