// Quadric simplification (core/mesh/quadric_simplification): flat regions collapse to few faces at
// no error, curved ones stay within the error asked, the surface stays a closed or bounded
// manifold of the same genus and orientation, boundaries and every kept vertex stay where they
// were, and the result is the same every time.
#include <gtest/gtest.h>

#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/point_triangle.h"
#include "core/mesh/quadric_simplification.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

int euler_characteristic(const TriMesh& m) {
  const EdgeTopology topo = edge_topology(m.F, m.num_vertices());
  std::vector<char> used(static_cast<size_t>(m.num_vertices()), 0);
  for (int f = 0; f < m.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) used[m.F(f, k)] = 1;
  int v = 0;
  for (const char u : used) v += u;
  return v - topo.num_edges() + m.num_faces();
}

void expect_manifold(const TriMesh& m, bool closed) {
  const EdgeTopology topo = edge_topology(m.F, m.num_vertices());
  int boundary = 0, bad = 0;
  for (int e = 0; e < topo.num_edges(); ++e) {
    boundary += topo.edge_faces.degree(e) == 1;
    bad += topo.edge_faces.degree(e) > 2;
  }
  EXPECT_EQ(bad, 0) << "non-manifold edges";
  if (closed) {
    EXPECT_EQ(boundary, 0) << "holes opened";
  }
}

double enclosed_volume(const TriMesh& m) {
  double v = 0;
  for (int f = 0; f < m.num_faces(); ++f)
    v += Vector3d(m.V.row(m.F(f, 0))).dot(Vector3d(m.V.row(m.F(f, 1))).cross(m.V.row(m.F(f, 2)))) /
         6;
  return v;
}

// Distance from p to the nearest face of m (brute force).
double distance_to(const TriMesh& m, const Vector3d& p) {
  double best = kInf;
  for (int f = 0; f < m.num_faces(); ++f) {
    const Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    best = std::min(best, std::sqrt(point_triangle_squared_distance(p, a, b, c)));
  }
  return best;
}

TEST(QuadricSimplification, AFlatGridBecomesAFewFacesWithItsBorderKept) {
  const TriMesh grid = test::plane_grid(4, 3, 40, 30);
  QuadricSimplificationOptions o;
  o.max_error = 1e-9;
  const QuadricSimplification s = simplify_by_quadrics(grid, o);
  EXPECT_LT(s.mesh.num_faces(), grid.num_faces() / 4);
  EXPECT_LE(s.max_error, 1e-9);
  EXPECT_NEAR(face_areas(s.mesh.V, s.mesh.F).sum(), 12.0, 1e-9);
  expect_manifold(s.mesh, false);
  for (int f = 0; f < s.mesh.num_faces(); ++f) {
    const Vector3d a = s.mesh.V.row(s.mesh.F(f, 0)), b = s.mesh.V.row(s.mesh.F(f, 1)),
                   c = s.mesh.V.row(s.mesh.F(f, 2));
    EXPECT_GT((b - a).cross(c - a).z(), 0) << "face " << f << " flipped";
  }
  // Every boundary vertex of the grid is still there, where it was.
  int border = 0, kept = 0;
  std::vector<char> in(static_cast<size_t>(grid.num_vertices()), 0);
  for (const int v : s.origin_vertex) in[v] = 1;
  for (int v = 0; v < grid.num_vertices(); ++v) {
    const double x = grid.V(v, 0), y = grid.V(v, 1);
    if (x == 0 || y == 0 || std::abs(x - 4) < 1e-12 || std::abs(y - 3) < 1e-12) {
      ++border;
      kept += in[v];
    }
  }
  EXPECT_EQ(kept, border);
  for (size_t i = 0; i < s.origin_vertex.size(); ++i)
    EXPECT_EQ(s.mesh.V.row(static_cast<Eigen::Index>(i)), grid.V.row(s.origin_vertex[i]));
}

TEST(QuadricSimplification, ALongestEdgeBoundsTheCollapses) {
  const TriMesh grid = test::plane_grid(4, 4, 40, 40);
  QuadricSimplificationOptions o;
  o.max_error = 1e-9;
  o.max_edge_length = 0.5;
  const QuadricSimplification s = simplify_by_quadrics(grid, o);
  EXPECT_LT(s.mesh.num_faces(), grid.num_faces() / 4);
  for (int f = 0; f < s.mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_LE((s.mesh.V.row(s.mesh.F(f, k)) - s.mesh.V.row(s.mesh.F(f, (k + 1) % 3))).norm(),
                0.5 + 1e-12);
}

TEST(QuadricSimplification, ASphereStaysWithinTheErrorAskedAndClosed) {
  TriMesh sphere = test::icosphere(5);  // 20,480 faces, radius 1
  const double tolerance = 0.01;
  QuadricSimplificationOptions o;
  o.max_error = tolerance;
  const QuadricSimplification s = simplify_by_quadrics(sphere, o);
  std::printf("[ measure  ] sphere: %d -> %d faces, largest quadric error %.2e\n",
              sphere.num_faces(), s.mesh.num_faces(), s.max_error);
  EXPECT_LT(s.mesh.num_faces(), sphere.num_faces() / 2);
  EXPECT_LE(s.max_error, tolerance);
  expect_manifold(s.mesh, true);
  EXPECT_EQ(euler_characteristic(s.mesh), 2);
  EXPECT_GT(enclosed_volume(s.mesh), 0) << "orientation kept";
  // No sliver: every face at least the quality asked (the icosphere's are all above it).
  for (int f = 0; f < s.mesh.num_faces(); ++f) {
    const Vector3d a = s.mesh.V.row(s.mesh.F(f, 0)), b = s.mesh.V.row(s.mesh.F(f, 1)),
                   c = s.mesh.V.row(s.mesh.F(f, 2));
    const double q = 2 * std::sqrt(3.0) * (b - a).cross(c - a).norm() /
                     ((b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm());
    EXPECT_GE(q, o.min_quality) << "face " << f;
  }
  // The input surface stays near: its vertices within the tolerance of the simplified faces.
  double worst = 0;
  for (int v = 0; v < sphere.num_vertices(); v += 7)
    worst = std::max(worst, distance_to(s.mesh, sphere.V.row(v).transpose()));
  EXPECT_LE(worst, tolerance) << "an input vertex is " << worst << " from the simplified surface";
}

TEST(QuadricSimplification, ATorusKeepsItsGenus) {
  TriMesh torus = test::midpoint_split(test::torus(2.0, 0.7, 48, 16));
  QuadricSimplificationOptions o;
  o.max_error = 0.02;
  const QuadricSimplification s = simplify_by_quadrics(torus, o);
  EXPECT_LT(s.mesh.num_faces(), torus.num_faces() / 2);
  expect_manifold(s.mesh, true);
  EXPECT_EQ(euler_characteristic(s.mesh), 0);
}

TEST(QuadricSimplification, NoCollapseAtZeroErrorOnACurvedSurface) {
  const TriMesh sphere = test::icosphere(2);
  QuadricSimplificationOptions o;
  o.max_error = 0;
  const QuadricSimplification s = simplify_by_quadrics(sphere, o);
  EXPECT_EQ(s.collapses, 0);
  EXPECT_EQ(s.mesh.F, sphere.F);
  EXPECT_EQ(s.mesh.V, sphere.V);
}

TEST(QuadricSimplification, SameResultEveryTime) {
  const TriMesh torus = test::torus(2.0, 0.7, 48, 16);
  QuadricSimplificationOptions o;
  o.max_error = 0.05;
  const QuadricSimplification a = simplify_by_quadrics(torus, o);
  const QuadricSimplification b = simplify_by_quadrics(torus, o);
  EXPECT_EQ(a.mesh.F, b.mesh.F);
  EXPECT_EQ(a.origin_face, b.origin_face);
  ASSERT_EQ(a.origin_face.size(), static_cast<size_t>(a.mesh.num_faces()));
  for (const int f : a.origin_face) EXPECT_TRUE(f >= 0 && f < torus.num_faces());
}

TEST(QuadricSimplification, BadOptionsAndMeshesAreRefused) {
  const TriMesh grid = test::plane_grid(1, 1, 2, 2);
  QuadricSimplificationOptions o;
  o.max_error = -1;
  EXPECT_THROW(simplify_by_quadrics(grid, o), InvalidInput);
  o.max_error = std::nan("");
  EXPECT_THROW(simplify_by_quadrics(grid, o), InvalidInput);
  o.max_error = 0.1;
  o.max_edge_length = 0;
  EXPECT_THROW(simplify_by_quadrics(grid, o), InvalidInput);
  o.max_edge_length = kInf;
  o.max_normal_turn_degrees = 180;
  EXPECT_THROW(simplify_by_quadrics(grid, o), InvalidInput);
  o.max_normal_turn_degrees = 45;
  o.min_quality = 1.5;
  EXPECT_THROW(simplify_by_quadrics(grid, o), InvalidInput);
  EXPECT_THROW(o.validate(), InvalidInput);
  o.min_quality = 0.3;
  EXPECT_NO_THROW(o.validate());
  TriMesh bad = grid;
  bad.F(0, 0) = 99;
  EXPECT_THROW(simplify_by_quadrics(bad, o), InvalidInput);
  bad = grid;
  bad.V(0, 0) = std::nan("");
  EXPECT_THROW(simplify_by_quadrics(bad, o), InvalidInput);
}

}  // namespace
}  // namespace mq
