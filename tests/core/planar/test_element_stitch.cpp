#include <gtest/gtest.h>

#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/boundary_loops.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/element_cut.h"
#include "core/planar/element_stitch.h"
#include "tests/core/planar/cut_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Cuts `mesh` against `other` (section 2.7) and returns the kept part. Faces with centroid x on
// the keep side of keep_x are hard Keep, on the far side of remove_x hard Remove.
TriMesh cut_against(const TriMesh& mesh, const TriMesh& other, double keep_x, double remove_x) {
  const bool left = keep_x < remove_x;
  std::vector<CutLabel> hard(mesh.num_faces(), CutLabel::Free);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const double x = test::face_centroid(mesh, f).x();
    if (left ? x < keep_x : x > keep_x) hard[f] = CutLabel::Keep;
    if (left ? x > remove_x : x < remove_x) hard[f] = CutLabel::Remove;
  }
  const Eigen::VectorXd d = test::distance_to_mesh(mesh.V, other);
  const std::vector<bool> keep = graph_cut_keep_faces(mesh.V, mesh.F, d, hard);
  std::vector<int> kept;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (keep[f]) kept.push_back(f);
  return extract_faces(mesh, kept);
}

// Faces of `mesh` whose centroid satisfies pred.
template <typename Pred>
TriMesh select(const TriMesh& mesh, Pred pred) {
  std::vector<int> faces;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (pred(test::face_centroid(mesh, f))) faces.push_back(f);
  TriMesh part = extract_faces(mesh, faces);
  return part;
}

int euler_characteristic(const TriMesh& m) {
  return m.num_vertices() - edge_topology(m.F, m.num_vertices()).num_edges() + m.num_faces();
}

// Every edge is used once in each direction: closed and consistently oriented.
void expect_consistently_oriented_closed(const TriMesh& m) {
  const auto counts = test::directed_edge_counts(m.F);
  for (const auto& [edge, count] : counts) {
    EXPECT_EQ(count, 1) << edge.first << "->" << edge.second;
    EXPECT_EQ(counts.count({edge.second, edge.first}), 1u) << edge.first << "->" << edge.second;
  }
}

void expect_seam_constraints(const StitchResult& r, const TriMesh& A, const TriMesh& B) {
  const int seam_vertices = static_cast<int>(boundary_loops(A.F, A.num_vertices())[0].size()) * 0 +
                            static_cast<int>(r.constraints.size());
  EXPECT_GT(seam_vertices, 0);
  for (const LinearConstraint& c : r.constraints) {
    ASSERT_GE(c.vertices[0], 0);
    ASSERT_LT(c.vertices[0], r.mesh.num_vertices());
    EXPECT_EQ(c.vertices[1], -1);
    EXPECT_EQ(c.weights[0], 1.0);
    // The target is halfway to the opposite part: closer to the other part's vertex set than
    // the vertex itself, and within half the seam gap.
    const Vector3d p = r.mesh.V.row(c.vertices[0]).transpose();
    const bool in_a = c.vertices[0] < A.num_vertices();
    const TriMesh& other = in_a ? B : A;
    double gap = std::numeric_limits<double>::infinity();
    for (int v = 0; v < other.num_vertices(); ++v)
      gap = std::min(gap, (other.V.row(v).transpose() - p).norm());
    EXPECT_LE((c.target - p).norm(), 0.5 * gap + 1e-12);
  }
}

TEST(BoundaryLoops, GridTubeAndClosedMesh) {
  const TriMesh grid = test::plane_grid(2, 1, 4, 3);
  const auto loops = boundary_loops(grid.F, grid.num_vertices());
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].size(), 14u);
  EXPECT_EQ(loops[0][0], 0);
  // Counter-clockwise seen from +z, like the faces: positive signed area.
  double area = 0;
  for (size_t i = 0; i < loops[0].size(); ++i) {
    const auto p = grid.V.row(loops[0][i]), q = grid.V.row(loops[0][(i + 1) % loops[0].size()]);
    area += 0.5 * (p.x() * q.y() - q.x() * p.y());
  }
  EXPECT_NEAR(area, 2.0, 1e-12);
  const TriMesh tube = test::tube(0, 1, 3, 7, 0.5, 0, false);
  const auto tube_loops = boundary_loops(tube.F, tube.num_vertices());
  ASSERT_EQ(tube_loops.size(), 2u);
  EXPECT_EQ(tube_loops[0].size(), 7u);
  EXPECT_EQ(tube_loops[1].size(), 7u);
  EXPECT_TRUE(boundary_loops(test::torus(1, 0.3, 8, 6).F, 48).empty());
}

TEST(BoundaryLoops, RejectsNonManifoldBoundaryVertex) {
  // Two triangles touching at vertex 0 only.
  MatrixX3i F(2, 3);
  F << 0, 1, 2, 0, 3, 4;
  EXPECT_THROW(boundary_loops(F, 5), TopologyError);
  F << 0, 1, 2, 0, 1, 3;  // shared edge used twice in the same direction
  EXPECT_THROW(boundary_loops(F, 4), TopologyError);
  EXPECT_THROW(boundary_loops(F, 3), InvalidInput);
}

TEST(ElementStitch, CappedTubeHalvesBecomeOneClosedSurface) {
  // Two differently sampled, overlapping capped tubes: A over x < 0.1, B over x > -0.1.
  const TriMesh a_full = test::tube(-1.0, 0.1, 22, 16, 0.3, 0.0, true);
  const TriMesh b_full = test::tube(-0.1, 1.0, 20, 14, 0.3, 0.1, true);
  const TriMesh A = cut_against(a_full, b_full, -0.1, 0.0);
  const TriMesh B = cut_against(b_full, a_full, 0.1, 0.0);
  ASSERT_EQ(boundary_loops(A.F, A.num_vertices()).size(), 1u);
  ASSERT_EQ(boundary_loops(B.F, B.num_vertices()).size(), 1u);

  const std::optional<StitchResult> r = stitch_cut_elements(A, B);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->bridged_loops, 1);
  EXPECT_EQ(r->mesh.num_vertices(), A.num_vertices() + B.num_vertices());
  EXPECT_TRUE(r->mesh.V.topRows(A.num_vertices()) == A.V);
  const TopologyReport report = topology_report(r->mesh);
  EXPECT_EQ(report.num_components, 1);
  EXPECT_TRUE(report.closed());
  EXPECT_TRUE(report.manifold());
  EXPECT_EQ(report.num_degenerate_faces, 0);
  EXPECT_EQ(euler_characteristic(r->mesh), 2);
  expect_consistently_oriented_closed(r->mesh);

  // Bridge triangles: non-degenerate and facing outwards like the tube.
  const MatrixX3d normals = face_normals(r->mesh.V, r->mesh.F);
  const Eigen::VectorXd areas = face_areas(r->mesh.V, r->mesh.F);
  const int first_bridge = A.num_faces() + B.num_faces();
  ASSERT_EQ(r->mesh.num_faces() - first_bridge,
            static_cast<int>(boundary_loops(A.F, A.num_vertices())[0].size() +
                             boundary_loops(B.F, B.num_vertices())[0].size()));
  for (int f = first_bridge; f < r->mesh.num_faces(); ++f) {
    EXPECT_GT(areas(f), 1e-4) << f;
    const Vector3d c = test::face_centroid(r->mesh, f);
    const Vector3d radial(0, c.y(), c.z());
    EXPECT_GT(normals.row(f).dot(radial.normalized()), 0.5) << f;
  }
  EXPECT_EQ(r->constraints.size(), static_cast<size_t>(r->mesh.num_faces() - first_bridge));
  expect_seam_constraints(*r, A, B);

  // Deterministic.
  const std::optional<StitchResult> again = stitch_cut_elements(A, B);
  ASSERT_TRUE(again.has_value());
  EXPECT_TRUE(again->mesh.F == r->mesh.F);
}

TEST(ElementStitch, TorusHalvesStitchBackIntoAGenusOneSurface) {
  const TriMesh ta = test::torus(1.0, 0.3, 48, 12);
  TriMesh tb = test::torus(1.0, 0.3, 44, 10);
  // Rotate B slightly about z so the two samplings never coincide.
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(0.03, Vector3d::UnitZ()).toRotationMatrix();
  tb.V = (tb.V * rot.transpose()).eval();
  const TriMesh a_part = select(ta, [](const Vector3d& c) { return c.x() < 0.3; });
  const TriMesh b_part = select(tb, [](const Vector3d& c) { return c.x() > -0.3; });
  const TriMesh A = cut_against(a_part, b_part, -0.3, 0.0);
  const TriMesh B = cut_against(b_part, a_part, 0.3, 0.0);
  ASSERT_EQ(boundary_loops(A.F, A.num_vertices()).size(), 2u);
  ASSERT_EQ(boundary_loops(B.F, B.num_vertices()).size(), 2u);

  const std::optional<StitchResult> r = stitch_cut_elements(A, B);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->bridged_loops, 2);
  const TopologyReport report = topology_report(r->mesh);
  EXPECT_EQ(report.num_components, 1);
  EXPECT_TRUE(report.closed());
  EXPECT_TRUE(report.manifold());
  EXPECT_EQ(report.num_degenerate_faces, 0);
  EXPECT_EQ(euler_characteristic(r->mesh), 0);
  expect_consistently_oriented_closed(r->mesh);
  expect_seam_constraints(*r, A, B);
}

TEST(ElementStitch, OpenTubeFarEndsStayOpen) {
  // Uncapped tubes: the far ends are not mutual nearest loops and are left open.
  const TriMesh a_full = test::tube(-1.0, 0.1, 22, 16, 0.3, 0.0, false);
  const TriMesh b_full = test::tube(-0.1, 1.0, 20, 14, 0.3, 0.1, false);
  const TriMesh A = cut_against(a_full, b_full, -0.1, 0.0);
  const TriMesh B = cut_against(b_full, a_full, 0.1, 0.0);
  const std::optional<StitchResult> r = stitch_cut_elements(A, B);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->bridged_loops, 1);
  const TopologyReport report = topology_report(r->mesh);
  EXPECT_EQ(report.num_components, 1);
  EXPECT_EQ(report.num_boundary_edges, 16 + 14);  // the two far ends only
  const auto loops = boundary_loops(r->mesh.F, r->mesh.num_vertices());
  ASSERT_EQ(loops.size(), 2u);
  for (const auto& loop : loops)
    for (int v : loop) EXPECT_NEAR(std::abs(r->mesh.V(v, 0)), 1.0, 1e-12);
}

TEST(ElementStitch, RefusesLoopsTooFarApartOrMissing) {
  const TriMesh a_full = test::tube(-1.0, 0.1, 22, 16, 0.3, 0.0, true);
  const TriMesh b_full = test::tube(-0.1, 1.0, 20, 14, 0.3, 0.1, true);
  const TriMesh A = cut_against(a_full, b_full, -0.1, 0.0);
  TriMesh B = cut_against(b_full, a_full, 0.1, 0.0);
  // A B part that is flipped winds the same way as A at the seam: not compatible.
  TriMesh flipped = B;
  flipped.F.col(1).swap(flipped.F.col(2));
  EXPECT_FALSE(stitch_cut_elements(A, flipped).has_value());
  StitchOptions options;
  options.max_loop_distance = 0.5;
  EXPECT_TRUE(stitch_cut_elements(A, B, options).has_value());
  B.V.col(0).array() += 5.0;
  EXPECT_FALSE(stitch_cut_elements(A, B, options).has_value());
  // A closed B has no seam loop.
  EXPECT_FALSE(stitch_cut_elements(A, b_full).has_value());
  EXPECT_FALSE(stitch_cut_elements(A, TriMesh{}).has_value());
}

TEST(ElementStitch, RejectsBadInput) {
  TriMesh A = test::tube(0, 1, 3, 6, 0.3, 0, false);
  const TriMesh B = test::tube(1.2, 2, 3, 6, 0.3, 0, false);
  StitchOptions bad;
  bad.max_loop_distance = -1;
  EXPECT_THROW(stitch_cut_elements(A, B, bad), InvalidInput);
  bad.max_loop_distance = std::nan("");
  EXPECT_THROW(stitch_cut_elements(A, B, bad), InvalidInput);
  A.V(0, 0) = std::nan("");
  EXPECT_THROW(stitch_cut_elements(A, B), InvalidInput);
  A = test::tube(0, 1, 3, 6, 0.3, 0, false);
  A.F(0, 0) = 999;
  EXPECT_THROW(stitch_cut_elements(A, B), InvalidInput);
}

}  // namespace
}  // namespace mq
