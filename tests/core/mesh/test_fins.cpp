// Fins: pieces sticking out of a larger surface at non-manifold edges (core/mesh/fins.h).
#include <gtest/gtest.h>

#include "core/mesh/fins.h"
#include "core/mesh/mesh_topology.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Appends a vertex and returns its index.
int add_vertex(TriMesh& m, const Vector3d& p) {
  m.V.conservativeResize(m.V.rows() + 1, 3);
  m.V.row(m.V.rows() - 1) = p.transpose();
  return static_cast<int>(m.V.rows()) - 1;
}

void add_face(TriMesh& m, int a, int b, int c) {
  m.F.conservativeResize(m.F.rows() + 1, 3);
  m.F.row(m.F.rows() - 1) << a, b, c;
}

// A triangle standing up from the interior edge (a, b) of `m`, its apex `height` above the
// edge's midpoint.
void add_fin(TriMesh& m, int a, int b, double height) {
  const Vector3d mid = 0.5 * (m.V.row(a) + m.V.row(b)).transpose();
  add_face(m, a, b, add_vertex(m, mid + Vector3d(0, 0, height)));
}

// An interior edge of the grid (two faces), the k-th found.
std::pair<int, int> interior_edge(const TriMesh& m, int k) {
  const EdgeTopology topo = edge_topology(m.F, m.num_vertices());
  for (int e = 0; e < topo.num_edges(); ++e)
    if (topo.edge_faces.degree(e) == 2 && k-- == 0) return {topo.E(e, 0), topo.E(e, 1)};
  return {-1, -1};
}

TEST(Fins, ManifoldMeshesHaveNone) {
  EXPECT_TRUE(fin_faces(test::unit_cube()).empty());
  EXPECT_TRUE(fin_faces(test::plane_grid(4, 4, 8, 8)).empty());
  EXPECT_TRUE(fin_faces(test::torus(2, 0.5, 16, 8)).empty());
}

TEST(Fins, TrianglesStandingOnAGridAreFinsAndTheGridIsNot) {
  TriMesh m = test::plane_grid(4, 4, 8, 8);
  const int grid_faces = m.num_faces();
  for (int k : {3, 40, 90}) {
    const auto [a, b] = interior_edge(m, k);
    add_fin(m, a, b, 0.3);
  }
  EXPECT_EQ(topology_report(m).num_non_manifold_edges, 3);
  int left = -1;
  EXPECT_EQ(fin_faces(m, 10.0, &left),
            (std::vector<int>{grid_faces, grid_faces + 1, grid_faces + 2}));
  EXPECT_EQ(left, 0);
}

TEST(Fins, AFinOfSeveralFacesIsOnePiece) {
  // Two triangles joined along their shared edge, standing on one interior edge: both go.
  TriMesh m = test::plane_grid(4, 4, 8, 8);
  const int grid_faces = m.num_faces();
  const auto [a, b] = interior_edge(m, 50);
  const Vector3d mid = 0.5 * (m.V.row(a) + m.V.row(b)).transpose();
  const int c = add_vertex(m, mid + Vector3d(0, 0, 0.5));
  const int d = add_vertex(m, m.V.row(b).transpose() + Vector3d(0, 0, 0.5));
  add_face(m, a, b, c);
  add_face(m, c, b, d);
  EXPECT_EQ(fin_faces(m), (std::vector<int>{grid_faces, grid_faces + 1}));
}

TEST(Fins, PiecesOfComparableSizeAreNotFins) {
  // Three sheets of one size meeting at an edge (an open book): none sticks out of another.
  TriMesh m;
  m.V.resize(8, 3);
  m.V << 0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 1, -1, 0, 0, -1, 0, 1, 0, 1, 0, 0, 1, 1;
  m.F.resize(6, 3);
  m.F << 0, 2, 3, 0, 3, 1, 0, 1, 5, 0, 5, 4, 0, 6, 7, 0, 7, 1;
  EXPECT_EQ(topology_report(m).num_non_manifold_edges, 1);
  int left = -1;
  EXPECT_TRUE(fin_faces(m, 10.0, &left).empty());
  EXPECT_EQ(left, 1);
  // A fin on a piece less than ten times its area is kept too.
  TriMesh small = test::plane_grid(1, 1, 2, 2);
  const auto [a, b] = interior_edge(small, 0);
  add_fin(small, a, b, 1.5);
  EXPECT_TRUE(fin_faces(small).empty());
  EXPECT_EQ(fin_faces(small, 1.2).size(), 1u);
}

TEST(Fins, TwoSidedSheetsAreNotFins) {
  // A sheet and its back (the same faces reversed) meet four to an interior edge.
  TriMesh m = test::plane_grid(2, 2, 4, 4);
  const Eigen::Index n = m.F.rows();
  m.F.conservativeResize(2 * n, 3);
  for (Eigen::Index f = 0; f < n; ++f) m.F.row(n + f) << m.F(f, 0), m.F(f, 2), m.F(f, 1);
  EXPECT_GT(topology_report(m).num_non_manifold_edges, 0);
  EXPECT_TRUE(fin_faces(m).empty());
}

}  // namespace
}  // namespace mq
