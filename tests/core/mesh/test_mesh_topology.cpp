#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(MeshTopology, CubeIsClosedManifoldSingleComponent) {
  const TriMesh cube = test::unit_cube();
  const TopologyReport r = topology_report(cube);
  EXPECT_EQ(r.num_components, 1);
  EXPECT_EQ(r.num_boundary_edges, 0);
  EXPECT_EQ(r.num_non_manifold_edges, 0);
  EXPECT_EQ(r.num_non_manifold_vertices, 0);
  EXPECT_TRUE(r.closed());
  const EdgeTopology topo = edge_topology(cube.F, cube.num_vertices());
  EXPECT_EQ(topo.num_edges(), 18);  // Euler: V - E + F = 2
  EXPECT_NEAR(surface_area(cube.V, cube.F), 6.0, 1e-12);
}

TEST(MeshTopology, CubeNormalsPointOutward) {
  const TriMesh cube = test::unit_cube();
  const MatrixX3d FN = face_normals(cube.V, cube.F);
  for (int f = 0; f < cube.num_faces(); ++f) {
    const Vector3d centroid =
        (cube.V.row(cube.F(f, 0)) + cube.V.row(cube.F(f, 1)) + cube.V.row(cube.F(f, 2))) / 3.0;
    EXPECT_GT(FN.row(f).dot(centroid - Vector3d(0.5, 0.5, 0.5)), 0.0) << "face " << f;
  }
  const MatrixX3d VN = vertex_normals(cube.V, cube.F);
  for (int v = 0; v < 8; ++v) EXPECT_NEAR(VN.row(v).norm(), 1.0, 1e-12);
}

TEST(MeshTopology, GridBoundaryAndAdjacency) {
  const TriMesh g = test::plane_grid(2.0, 1.0, 4, 2);
  const TopologyReport r = topology_report(g);
  EXPECT_EQ(r.num_boundary_edges, 2 * (4 + 2));
  EXPECT_FALSE(r.closed());
  EXPECT_TRUE(r.manifold());
  const Adjacency adj = vertex_adjacency(g.F, g.num_vertices());
  EXPECT_EQ(adj.degree(0), 3);  // corner with the diagonal
  EXPECT_EQ(adj.degree(6), 6);  // interior vertex
  const MatrixX3i TT = face_adjacency(edge_topology(g.F, g.num_vertices()));
  int boundary = 0;
  for (int f = 0; f < TT.rows(); ++f)
    for (int k = 0; k < 3; ++k) boundary += TT(f, k) < 0;
  EXPECT_EQ(boundary, 12);
}

TEST(MeshTopology, ComponentsExtractAndAppend) {
  TriMesh two = test::torus(2.0, 0.5, 12, 6);
  TriMesh other = test::unit_cube();
  append_mesh(two, other);
  std::vector<int> fc;
  ASSERT_EQ(connected_components(two.F, two.num_vertices(), fc), 2);
  const auto groups = component_faces(fc, 2);
  EXPECT_EQ(groups[0].size(), 144u);
  EXPECT_EQ(groups[1].size(), 12u);
  const TriMesh cube = extract_faces(two, groups[1]);
  EXPECT_EQ(cube.num_vertices(), 8);
  EXPECT_TRUE(topology_report(cube).closed());
  const TopologyReport torus_report = topology_report(extract_faces(two, groups[0]));
  EXPECT_TRUE(torus_report.closed());
  EXPECT_TRUE(torus_report.manifold());
}

// A part far smaller than the mesh is renumbered without a table over the whole mesh; the
// result (vertices in order of first use, the map back) is the table's, face order arbitrary.
TEST(MeshTopology, ExtractingASmallPartNumbersAsTheTableDoes) {
  const TriMesh grid = test::plane_grid(1.0, 1.0, 60, 60);  // 7,200 faces
  std::vector<int> small = {4000, 17, 3999, 18, 4001, 17 + 120, 4000 + 1};
  // The reference: the same renumbering written out by first use.
  std::vector<int> first_use;
  for (const int f : small)
    for (int k = 0; k < 3; ++k)
      if (std::find(first_use.begin(), first_use.end(), grid.F(f, k)) == first_use.end())
        first_use.push_back(grid.F(f, k));
  std::vector<int> map;
  const TriMesh part = extract_faces(grid, small, &map);  // 21 corners far apart: sorted
  EXPECT_EQ(map, first_use);
  ASSERT_EQ(part.num_faces(), static_cast<int>(small.size()));
  for (size_t i = 0; i < small.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(map[static_cast<size_t>(part.F(static_cast<Eigen::Index>(i), k))],
                grid.F(small[i], k));
      EXPECT_EQ(part.V.row(part.F(static_cast<Eigen::Index>(i), k)),
                grid.V.row(grid.F(small[i], k)));
    }
  // A small part whose vertices lie close in index (one element of an output) takes a table
  // over their range: the same numbering rule.
  const std::vector<int> close = {4001, 4000, 3998, 4003, 3999};
  std::vector<int> close_first_use;
  for (const int f : close)
    for (int k = 0; k < 3; ++k)
      if (std::find(close_first_use.begin(), close_first_use.end(), grid.F(f, k)) ==
          close_first_use.end())
        close_first_use.push_back(grid.F(f, k));
  std::vector<int> close_map;
  const TriMesh c = extract_faces(grid, close, &close_map);
  EXPECT_EQ(close_map, close_first_use);
  for (size_t i = 0; i < close.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(close_map[static_cast<size_t>(c.F(static_cast<Eigen::Index>(i), k))],
                grid.F(close[i], k));
  // Half of the mesh takes the table: the same numbering rule.
  std::vector<int> half;
  for (int f = 7199; f >= 3600; --f) half.push_back(f);
  std::vector<int> half_map;
  const TriMesh h = extract_faces(grid, half, &half_map);
  EXPECT_EQ(half_map[0], grid.F(7199, 0));
  for (size_t i = 0; i < half.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(half_map[static_cast<size_t>(h.F(static_cast<Eigen::Index>(i), k))],
                grid.F(half[i], k));
}

TEST(MeshTopology, NonManifoldEdgeAndVertexDetected) {
  TriMesh m;
  m.V.resize(7, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 2, 1, 0, 2, -1, 0;
  // Three triangles on edge (0,1): non-manifold edge; two more fans meeting at vertex 1.
  m.F.resize(5, 3);
  m.F << 0, 1, 2, 1, 0, 3, 0, 1, 4, 1, 5, 6, 1, 6, 5;
  const TopologyReport r = topology_report(m);
  EXPECT_EQ(r.num_non_manifold_edges, 1);
  EXPECT_GE(r.num_non_manifold_vertices, 1);
  EXPECT_FALSE(r.manifold());
}

TEST(MeshTopology, OutOfRangeIndexThrows) {
  TriMesh m = test::unit_cube();
  m.F(3, 1) = 99;
  EXPECT_THROW(topology_report(m), InvalidInput);
}

TEST(MeshTopology, RemoveUnreferencedKeepsOrder) {
  TriMesh m = test::unit_cube();
  m.V.conservativeResize(10, 3);
  m.V.row(8) << 5, 5, 5;
  m.V.row(9) << 6, 6, 6;
  m.F.array() += 0;
  remove_unreferenced_vertices(m);
  EXPECT_EQ(m.num_vertices(), 8);
  EXPECT_TRUE(topology_report(m).closed());
}

}  // namespace
}  // namespace mq

namespace mq {
namespace {

// The linear-time groupings must give exactly what sorting all pairs gives: on a real mesh,
// plus a duplicated face and a non-manifold fin, with an isolated vertex index at the end.
TEST(MeshTopology, EdgeTopologyAndAdjacencyMatchSortedReference) {
  TriMesh m = read_mesh(test::shared_data("base/bunny_igl_7k.off"));
  const int nv = m.num_vertices() + 1;
  MatrixX3i F(m.F.rows() + 2, 3);
  F.topRows(m.F.rows()) = m.F;
  F.row(m.F.rows()) = m.F.row(0);                              // duplicate
  F.row(m.F.rows() + 1) << m.F(5, 1), m.F(5, 0), m.F(100, 2);  // fin on edge of face 5
  const EdgeTopology topo = edge_topology(F, nv);

  std::vector<std::array<int, 3>> half;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      half.push_back({std::min(a, b), std::max(a, b), 3 * f + k});
    }
  std::sort(half.begin(), half.end());
  int e = -1;
  std::vector<std::vector<int>> edge_faces;
  for (size_t i = 0; i < half.size(); ++i) {
    if (i == 0 || half[i][0] != half[i - 1][0] || half[i][1] != half[i - 1][1]) {
      ++e;
      ASSERT_LT(e, topo.num_edges());
      EXPECT_EQ(topo.E(e, 0), half[i][0]);
      EXPECT_EQ(topo.E(e, 1), half[i][1]);
      edge_faces.emplace_back();
    }
    EXPECT_EQ(topo.FE(half[i][2] / 3, half[i][2] % 3), e);
    edge_faces.back().push_back(half[i][2] / 3);
  }
  ASSERT_EQ(e + 1, topo.num_edges());
  int non_manifold = 0;
  for (int k = 0; k < topo.num_edges(); ++k) {
    EXPECT_EQ(std::vector<int>(topo.edge_faces.begin(k), topo.edge_faces.end(k)), edge_faces[k]);
    non_manifold += topo.is_non_manifold(k);
  }
  EXPECT_GE(non_manifold, 3);  // the duplicate's edges and the fin's shared edge

  std::vector<std::set<int>> ring(nv);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      ring[F(f, k)].insert(F(f, (k + 1) % 3));
      ring[F(f, (k + 1) % 3)].insert(F(f, k));
    }
  const Adjacency adj = vertex_adjacency(F, nv);
  for (int v = 0; v < nv; ++v)
    EXPECT_EQ(std::vector<int>(adj.begin(v), adj.end(v)),
              std::vector<int>(ring[v].begin(), ring[v].end()));
  EXPECT_EQ(adj.degree(nv - 1), 0);
}

}  // namespace
}  // namespace mq
