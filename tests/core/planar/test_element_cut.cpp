#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/element_cut.h"
#include "tests/core/planar/cut_fixtures.h"

namespace mq {
namespace {

// Tube along x over [0, 3], 30 rings of 12 quads: Keep on x < 1, Remove on x > 2.
struct TubeCase {
  TriMesh mesh = test::tube(0.0, 3.0, 30, 12, 0.3, 0.0, true);
  std::vector<CutLabel> hard;
  TubeCase() {
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const double x = test::face_centroid(mesh, f).x();
      hard.push_back(x < 1.0 ? CutLabel::Keep : x > 2.0 ? CutLabel::Remove : CutLabel::Free);
    }
  }
};

TEST(ElementCut, CutFollowsTheCheapestRingOfEq7) {
  TubeCase c;
  // Distance to the other element is smallest at the ring x = 1.7 (a V-shaped profile).
  Eigen::VectorXd d(c.mesh.num_vertices());
  for (int v = 0; v < c.mesh.num_vertices(); ++v) d(v) = 0.5 * std::abs(c.mesh.V(v, 0) - 1.7);
  const ElementCut cut = element_graph_cut(c.mesh.V, c.mesh.F, d, c.hard);
  ASSERT_EQ(cut.keep.size(), static_cast<size_t>(c.mesh.num_faces()));
  std::vector<int> kept;
  for (int f = 0; f < c.mesh.num_faces(); ++f) {
    const double x = test::face_centroid(c.mesh, f).x();
    if (c.hard[f] == CutLabel::Keep) {
      EXPECT_TRUE(cut.keep[f]) << f;
    }
    if (c.hard[f] == CutLabel::Remove) {
      EXPECT_FALSE(cut.keep[f]) << f;
    }
    EXPECT_EQ(cut.keep[f], x < 1.7) << "face " << f << " at x = " << x;
    if (cut.keep[f]) kept.push_back(f);
  }
  std::vector<int> comp;
  const TriMesh kept_mesh = extract_faces(c.mesh, kept);
  EXPECT_EQ(connected_components(kept_mesh.F, kept_mesh.num_vertices(), comp), 1);
  // The max-flow value is the cost of the returned cut, and no ring cut is cheaper.
  EXPECT_NEAR(cut.flow, cut_cost(c.mesh.V, c.mesh.F, d, cut.keep), 1e-9 * cut.flow);
  const double ring_edge = 2 * 0.3 * std::sin(M_PI / 12);
  EXPECT_NEAR(cut.flow, 12 * (1 + ring_edge) * 1.0, 1e-9);
  for (int ring = 10; ring <= 20; ++ring) {
    std::vector<bool> alt(c.mesh.num_faces());
    for (int f = 0; f < c.mesh.num_faces(); ++f)
      alt[f] = test::face_centroid(c.mesh, f).x() < 0.1 * ring;
    EXPECT_GE(cut_cost(c.mesh.V, c.mesh.F, d, alt), cut.flow - 1e-9) << ring;
  }
}

// The network leaves out the edges between two Keep faces: the distances at vertices that only
// Keep faces use are not read, and Free faces bounded by Keep faces are still reached (kept).
TEST(ElementCut, KeepFacesAwayFromTheCutChangeNothing) {
  TubeCase c;
  Eigen::VectorXd d(c.mesh.num_vertices());
  for (int v = 0; v < c.mesh.num_vertices(); ++v) d(v) = 0.5 * std::abs(c.mesh.V(v, 0) - 1.7);
  const ElementCut cut = element_graph_cut(c.mesh.V, c.mesh.F, d, c.hard);
  std::vector<char> off_keep(c.mesh.num_vertices(), 0);
  for (int f = 0; f < c.mesh.num_faces(); ++f)
    if (c.hard[f] != CutLabel::Keep)
      for (int k = 0; k < 3; ++k) off_keep[c.mesh.F(f, k)] = 1;
  Eigen::VectorXd far = d;
  int changed = 0;
  for (int v = 0; v < c.mesh.num_vertices(); ++v)
    if (!off_keep[v]) {
      far(v) = 1e3 + v;
      ++changed;
    }
  ASSERT_GT(changed, 100);
  const ElementCut same = element_graph_cut(c.mesh.V, c.mesh.F, far, c.hard);
  EXPECT_EQ(same.keep, cut.keep);
  EXPECT_EQ(same.flow, cut.flow);
  // Keep also over 1.3 < x < 1.5: the Free band 1 < x < 1.3 lies between Keep faces only.
  std::vector<CutLabel> banded = c.hard;
  for (int f = 0; f < c.mesh.num_faces(); ++f) {
    const double x = test::face_centroid(c.mesh, f).x();
    if (x > 1.3 && x < 1.5) banded[f] = CutLabel::Keep;
  }
  const ElementCut b = element_graph_cut(c.mesh.V, c.mesh.F, d, banded);
  for (int f = 0; f < c.mesh.num_faces(); ++f)
    EXPECT_EQ(b.keep[f], test::face_centroid(c.mesh, f).x() < 1.7) << f;
  EXPECT_NEAR(b.flow, cut.flow, 1e-12 * cut.flow);
}

TEST(ElementCut, CutStaysInsideTheLowDistanceBand) {
  TubeCase c;
  // Flat low band over [1.35, 1.65]: every cut edge must lie in it.
  Eigen::VectorXd d(c.mesh.num_vertices());
  for (int v = 0; v < c.mesh.num_vertices(); ++v) {
    const double x = c.mesh.V(v, 0);
    d(v) = (x > 1.35 && x < 1.65) ? 0.01 : 2.0;
  }
  const std::vector<bool> keep = graph_cut_keep_faces(c.mesh.V, c.mesh.F, d, c.hard);
  const EdgeTopology topo = edge_topology(c.mesh.F, c.mesh.num_vertices());
  int cut_edges = 0;
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (topo.edge_faces.degree(e) != 2) continue;
    const int* fs = topo.edge_faces.begin(e);
    if (keep[fs[0]] == keep[fs[1]]) continue;
    ++cut_edges;
    for (int k = 0; k < 2; ++k) {
      const double x = c.mesh.V(topo.E(e, k), 0);
      EXPECT_GT(x, 1.35);
      EXPECT_LT(x, 1.65);
    }
  }
  EXPECT_EQ(cut_edges, 12);  // one ring
}

TEST(ElementCut, DeterministicAndIndependentOfFaceOrder) {
  TubeCase c;
  // Constant distance: every ring in the free zone costs the same; ties must still resolve
  // to the same faces whatever the face order (smallest SOURCE side).
  const Eigen::VectorXd d = Eigen::VectorXd::Constant(c.mesh.num_vertices(), 0.2);
  const std::vector<bool> keep = graph_cut_keep_faces(c.mesh.V, c.mesh.F, d, c.hard);
  EXPECT_EQ(keep, graph_cut_keep_faces(c.mesh.V, c.mesh.F, d, c.hard));
  const int nf = c.mesh.num_faces();
  std::vector<int> perm(nf);
  std::iota(perm.begin(), perm.end(), 0);
  std::reverse(perm.begin(), perm.end());
  std::rotate(perm.begin(), perm.begin() + nf / 3, perm.end());
  MatrixX3i F2(nf, 3);
  std::vector<CutLabel> hard2(nf);
  for (int i = 0; i < nf; ++i) {
    F2.row(i) = c.mesh.F.row(perm[i]);
    hard2[i] = c.hard[perm[i]];
  }
  const std::vector<bool> keep2 = graph_cut_keep_faces(c.mesh.V, F2, d, hard2);
  for (int i = 0; i < nf; ++i) EXPECT_EQ(keep2[i], keep[perm[i]]) << i;
  // Smallest source side: the cut is at the first ring after the Keep zone.
  for (int f = 0; f < nf; ++f) EXPECT_EQ(keep[f], test::face_centroid(c.mesh, f).x() < 1.0);
}

TEST(ElementCut, OneSidedAndUnlabelledComponents) {
  // Two disjoint tubes: the first labelled, the second not.
  TriMesh m = test::tube(0, 1, 5, 8, 0.2, 0, false);
  append_mesh(m, test::tube(3, 4, 5, 8, 0.2, 0, false));
  const int half = m.num_faces() / 2;
  const Eigen::VectorXd d = Eigen::VectorXd::Zero(m.num_vertices());
  std::vector<CutLabel> hard(m.num_faces(), CutLabel::Free);
  hard[0] = CutLabel::Remove;
  ElementCut cut = element_graph_cut(m.V, m.F, d, hard);
  for (int f = 0; f < m.num_faces(); ++f) EXPECT_EQ(cut.keep[f], f >= half) << f;
  EXPECT_EQ(cut.flow, 0.0);
  hard[0] = CutLabel::Keep;
  cut = element_graph_cut(m.V, m.F, d, hard);
  for (int f = 0; f < m.num_faces(); ++f) EXPECT_TRUE(cut.keep[f]) << f;
  EXPECT_TRUE(graph_cut_keep_faces(m.V, MatrixX3i(0, 3), d, {}).empty());
}

TEST(ElementCut, AdjacentKeepAndRemoveCutTheirSharedEdge) {
  TriMesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  Eigen::VectorXd d(4);
  d << 0.5, 0, 0.25, 0;
  const ElementCut cut = element_graph_cut(m.V, m.F, d, {CutLabel::Keep, CutLabel::Remove});
  EXPECT_EQ(cut.keep, (std::vector<bool>{true, false}));
  EXPECT_NEAR(cut.flow, (1 + std::sqrt(2.0)) * (1 + 0.5 + 0.25), 1e-12);
  EXPECT_NEAR(cut_cost(m.V, m.F, d, cut.keep), cut.flow, 1e-12);
}

TEST(ElementCut, RejectsBadInput) {
  TubeCase c;
  const Eigen::VectorXd d = Eigen::VectorXd::Zero(c.mesh.num_vertices());
  EXPECT_THROW(graph_cut_keep_faces(c.mesh.V, c.mesh.F, Eigen::VectorXd::Zero(3), c.hard),
               InvalidInput);
  EXPECT_THROW(graph_cut_keep_faces(c.mesh.V, c.mesh.F, d, {}), InvalidInput);
  Eigen::VectorXd bad = d;
  bad(4) = std::nan("");
  EXPECT_THROW(graph_cut_keep_faces(c.mesh.V, c.mesh.F, bad, c.hard), InvalidInput);
  bad(4) = -1;
  EXPECT_THROW(graph_cut_keep_faces(c.mesh.V, c.mesh.F, bad, c.hard), InvalidInput);
  MatrixX3d V = c.mesh.V;
  V(2, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(graph_cut_keep_faces(V, c.mesh.F, d, c.hard), InvalidInput);
  MatrixX3i F = c.mesh.F;
  F(0, 0) = c.mesh.num_vertices();
  EXPECT_THROW(graph_cut_keep_faces(c.mesh.V, F, d, c.hard), InvalidInput);
  EXPECT_THROW(cut_cost(c.mesh.V, c.mesh.F, d, std::vector<bool>(2)), InvalidInput);
}

}  // namespace
}  // namespace mq
