// Shell tetrahedra (paper section 3.2): conforming split, orientation, volume, TetGen check.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/shell/shell_tetrahedra.h"
#include "tests/core/shell_fixtures.h"

namespace mq {
namespace {

using Tri = std::array<int, 3>;

Tri sorted(int a, int b, int c) {
  Tri t = {a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

// Every tet face with the number of tets using it.
std::map<Tri, int> face_counts(const TetIndices& T) {
  std::map<Tri, int> count;
  const int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (const auto& f : faces) ++count[sorted(T(t, f[0]), T(t, f[1]), T(t, f[2]))];
  return count;
}

TriMesh flat_shell_top(const TriMesh& grid, double h) {
  TriMesh top = grid;
  top.V.col(2).array() += h;
  return top;
}

// A grid whose vertex ids are shuffled, so that the sort rule meets every parity.
TriMesh shuffled_grid(int nx, int ny, std::uint64_t seed) {
  TriMesh g = test::plane_grid(2.0, 1.0, nx, ny);
  std::mt19937_64 rng(seed);
  std::vector<int> perm(g.V.rows());
  for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = static_cast<int>(i);
  for (std::size_t i = perm.size() - 1; i > 0; --i) std::swap(perm[i], perm[rng() % (i + 1)]);
  MatrixX3d V(g.V.rows(), 3);
  for (Eigen::Index i = 0; i < g.V.rows(); ++i) V.row(perm[i]) = g.V.row(i);
  for (Eigen::Index f = 0; f < g.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) g.F(f, k) = perm[g.F(f, k)];
  g.V = V;
  return g;
}

TEST(ShellTetrahedra, FlatGridIsConformingAndFillsTheSlab) {
  const TriMesh g = shuffled_grid(7, 5, 3);
  const double h = 0.1;
  const TetMesh shell = shell_tetrahedra(g.V, flat_shell_top(g, h).V, g.F);
  ASSERT_EQ(shell.num_tets(), 3 * g.num_faces());
  ASSERT_EQ(shell.num_vertices(), 2 * g.num_vertices());
  const Eigen::VectorXd vol = tet_volumes(shell);
  EXPECT_GT(vol.minCoeff(), 0.0);
  EXPECT_NEAR(vol.sum(), 2.0 * 1.0 * h, 1e-12);

  // Conforming: a tet face is shared by at most two tets; those used once are exactly the
  // shell boundary: 2 #F cap triangles plus 2 per boundary edge on the side walls.
  const std::map<Tri, int> count = face_counts(shell.T);
  const MatrixX3i B = shell_boundary_faces(g.F, g.num_vertices());
  const TopologyReport report = topology_report(g);
  ASSERT_EQ(B.rows(), 2 * g.num_faces() + 2 * report.num_boundary_edges);
  std::map<Tri, int> boundary;
  for (Eigen::Index f = 0; f < B.rows(); ++f) boundary[sorted(B(f, 0), B(f, 1), B(f, 2))] = 1;
  ASSERT_EQ(boundary.size(), std::size_t(B.rows()));
  int once = 0;
  for (const auto& [tri, n] : count) {
    ASSERT_LE(n, 2);
    if (n == 1) {
      ++once;
      EXPECT_TRUE(boundary.count(tri));
    }
  }
  EXPECT_EQ(once, B.rows());
}

TEST(ShellTetrahedra, BoundaryFacesPointOutOfTheShell) {
  const TriMesh g = shuffled_grid(4, 3, 8);
  const TetMesh shell = shell_tetrahedra(g.V, flat_shell_top(g, 0.2).V, g.F);
  const MatrixX3i B = shell_boundary_faces(g.F, g.num_vertices());
  // The shell's centroid lies on the inner side of every boundary face of this convex slab.
  const Vector3d c = shell.V.colwise().mean();
  for (Eigen::Index f = 0; f < B.rows(); ++f) {
    const Vector3d a = shell.V.row(B(f, 0)), b = shell.V.row(B(f, 1)), d = shell.V.row(B(f, 2));
    EXPECT_GT((b - a).cross(d - a).dot(a - c), 0.0) << "boundary face " << f;
  }
  // Closed base: no side walls, so the boundary is 2 #F.
  const TriMesh s = test::icosphere(1);
  EXPECT_EQ(shell_boundary_faces(s.F, s.num_vertices()).rows(), 2 * s.num_faces());
}

TEST(ShellTetrahedra, OffsetBunnyShellIsConformingClosedAndValid) {
  const test::OffsetBase ob = test::offset_base("base/bunny_igl_7k.off");
  const TetMesh shell = shell_tetrahedra(ob.base.V, ob.offset.V, ob.base.F);
  EXPECT_GT(tet_volumes(shell).minCoeff(), 0.0);
  const std::map<Tri, int> count = face_counts(shell.T);
  int once = 0;
  for (const auto& [tri, n] : count) {
    ASSERT_LE(n, 2);
    once += n == 1;
  }
  EXPECT_EQ(once, 2 * ob.base.num_faces());  // closed base: only the two caps
  const ShellValidation check = validate_shell(ob.base.V, ob.offset.V, ob.base.F);
  EXPECT_TRUE(check.valid()) << check.num_nonpositive_tets << " bad tets, "
                             << check.intersecting_boundary_faces.size()
                             << " intersecting boundary faces";
  EXPECT_EQ(check.num_tets, shell.num_tets());
  EXPECT_GT(check.min_volume, 0.0);
}

TEST(ShellTetrahedra, InvertedOffsetThrowsAndIsReported) {
  const TriMesh s = test::icosphere(2);
  const MatrixX3d inward = 0.9 * s.V;  // offset on the wrong side of every face
  EXPECT_THROW(shell_tetrahedra(s.V, inward, s.F), TopologyError);
  const ShellValidation check = validate_shell(s.V, inward, s.F);
  EXPECT_FALSE(check.valid());
  EXPECT_EQ(check.num_nonpositive_tets, check.num_tets);
  EXPECT_THROW(shell_tetrahedra(s.V, s.V, s.F), TopologyError);  // zero height: degenerate
}

TEST(ShellTetrahedra, TetgenFindsAFoldedOffset) {
  const TriMesh g = test::plane_grid(1.0, 1.0, 6, 6);
  TriMesh top = flat_shell_top(g, 0.1);
  EXPECT_TRUE(validate_shell(g.V, top.V, g.F).valid());
  // Push one interior offset vertex through the base: its cap faces cross the base.
  int centre = 0;
  for (int i = 0; i < g.num_vertices(); ++i)
    if ((g.V.row(i) - Eigen::RowVector3d(0.5, 0.5, 0)).norm() < 1e-9) centre = i;
  top.V(centre, 2) = -0.3;
  const ShellValidation check = validate_shell(g.V, top.V, g.F);
  EXPECT_FALSE(check.valid());
  EXPECT_GT(check.num_nonpositive_tets, 0);
  ASSERT_FALSE(check.intersecting_boundary_faces.empty());
  // TetGen agrees with the double-precision broad phase on which faces intersect.
  const MatrixX3i B = shell_boundary_faces(g.F, g.num_vertices());
  MatrixX3d S(2 * g.num_vertices(), 3);
  S << g.V, top.V;
  IntersectionOptions all;
  all.between_components_only = false;
  std::vector<int> ours;
  for (const auto& [f, h] : intersecting_face_pairs(S, B, all)) {
    ours.push_back(f);
    ours.push_back(h);
  }
  std::sort(ours.begin(), ours.end());
  ours.erase(std::unique(ours.begin(), ours.end()), ours.end());
  EXPECT_EQ(check.intersecting_boundary_faces, ours);
}

TEST(ShellTetrahedra, TetgenIntersectionsOfTwoCubes) {
  TriMesh a = test::unit_cube();
  TriMesh b = test::unit_cube();
  b.V.col(0).array() += 3.0;
  TriMesh both = a;
  append_mesh(both, b);
  EXPECT_TRUE(tetgen_intersecting_faces(both.V, both.F).empty());
  both.V.bottomRows(8).col(0).array() -= 2.5;  // now overlapping by half
  const std::vector<int> hit = tetgen_intersecting_faces(both.V, both.F);
  EXPECT_FALSE(hit.empty());
  EXPECT_TRUE(std::is_sorted(hit.begin(), hit.end()));
  EXPECT_EQ(hit, tetgen_intersecting_faces(both.V, both.F));  // deterministic
}

TEST(ShellTetrahedra, InvalidInputThrows) {
  const TriMesh g = test::plane_grid(1.0, 1.0, 2, 2);
  const MatrixX3d top = flat_shell_top(g, 0.1).V;
  EXPECT_THROW(shell_tetrahedra(g.V, top.topRows(3), g.F), InvalidInput);
  MatrixX3d bad = top;
  bad(1, 1) = std::nan("");
  EXPECT_THROW(shell_tetrahedra(g.V, bad, g.F), InvalidInput);
  MatrixX3i F = g.F;
  F(0, 0) = g.num_vertices();
  EXPECT_THROW(shell_tetrahedra(g.V, top, F), InvalidInput);
  EXPECT_THROW(shell_tet_indices(F, g.num_vertices()), InvalidInput);
  F = g.F;
  F(0, 1) = F(0, 0);
  EXPECT_THROW(shell_tetrahedra(g.V, top, F), InvalidInput);
  EXPECT_THROW(shell_boundary_faces(F, g.num_vertices()), InvalidInput);
  EXPECT_THROW(validate_shell(g.V, bad, g.F), InvalidInput);
  // A zero-area face never reaches TetGen.
  MatrixX3d flat = g.V;
  flat.row(g.F(0, 0)) = flat.row(g.F(0, 1));
  EXPECT_THROW(tetgen_intersecting_faces(flat, g.F), InvalidInput);
  TetMesh t;
  t.V = g.V;
  t.T.resize(1, 4);
  t.T << 0, 1, 2, 99;
  EXPECT_THROW(tet_volumes(t), InvalidInput);
}

}  // namespace
}  // namespace mq
