#include "core/midpoint_subdivision.h"

#include "core/geometry_measures.h"
#include "core/mesh_topology.h"

namespace mq {

TriMesh midpoint_subdivide(const TriMesh& mesh) {
  const int nv = mesh.num_vertices();
  const EdgeTopology topo = edge_topology(mesh.F, nv);
  TriMesh out;
  out.V.resize(nv + topo.num_edges(), 3);
  out.V.topRows(nv) = mesh.V;
  for (int e = 0; e < topo.num_edges(); ++e)
    out.V.row(nv + e) = 0.5 * (mesh.V.row(topo.E(e, 0)) + mesh.V.row(topo.E(e, 1)));
  out.F.resize(4 * mesh.F.rows(), 3);
  for (int f = 0; f < mesh.F.rows(); ++f) {
    // m_k is the midpoint of the edge from corner k to corner k+1.
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int mab = nv + topo.FE(f, 0), mbc = nv + topo.FE(f, 1), mca = nv + topo.FE(f, 2);
    out.F.row(4 * f + 0) << a, mab, mca;
    out.F.row(4 * f + 1) << mab, b, mbc;
    out.F.row(4 * f + 2) << mca, mbc, c;
    out.F.row(4 * f + 3) << mab, mbc, mca;
  }
  return out;
}

TriMesh refine_to_edge_length(const TriMesh& mesh, double max_mean_edge, int max_faces,
                              int* levels) {
  TriMesh m = mesh;
  int n = 0;
  while (mean_edge_length(m.V, m.F) > max_mean_edge &&
         4LL * m.F.rows() <= static_cast<long long>(max_faces)) {
    m = midpoint_subdivide(m);
    ++n;
  }
  if (levels) *levels = n;
  return m;
}

}  // namespace mq
