#include "core/mesh/boundary_loops.h"

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

std::vector<std::vector<int>> boundary_loops(const MatrixX3i& F, int num_vertices) {
  const EdgeTopology topo = edge_topology(F, num_vertices);
  std::vector<int> next(num_vertices, -1);
  std::vector<int> in_count(num_vertices, 0);
  for (int e = 0; e < topo.num_edges(); ++e)
    MQ_CHECK(!topo.is_non_manifold(e), TopologyError, "edge (", topo.E(e, 0), ", ", topo.E(e, 1),
             ") is used by ", topo.edge_faces.degree(e), " faces");
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      if (!topo.is_boundary(topo.FE(f, k))) continue;
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      MQ_CHECK(a != b, TopologyError, "degenerate boundary edge at vertex ", a, " of face ", f);
      MQ_CHECK(next[a] < 0, TopologyError, "non-manifold boundary vertex ", a,
               " (two outgoing boundary edges)");
      next[a] = b;
      ++in_count[b];
    }
  for (int v = 0; v < num_vertices; ++v)
    MQ_CHECK((next[v] >= 0 ? 1 : 0) == in_count[v], TopologyError,
             "non-manifold or inconsistently oriented boundary at vertex ", v);
  std::vector<std::vector<int>> loops;
  std::vector<char> visited(num_vertices, 0);
  for (int start = 0; start < num_vertices; ++start) {
    if (next[start] < 0 || visited[start]) continue;
    std::vector<int> loop;
    for (int v = start; !visited[v]; v = next[v]) {
      visited[v] = 1;
      loop.push_back(v);
    }
    // Every boundary vertex has in- and out-degree one, so the walk closes at start.
    MQ_ASSERT(next[loop.back()] == start);
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace mq
