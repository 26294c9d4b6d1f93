// Cone placement: poles are split, cones move to where the flat metric scales the surface
// least, and the indices keep their sum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "core/surface/cone_placement.h"
#include "tests/core/shell_fixtures.h"

namespace mq {
namespace {

int nearest_vertex(const TriMesh& m, const Vector3d& d) {
  int best = 0;
  for (int v = 1; v < m.num_vertices(); ++v)
    if ((m.V.row(v).transpose() - d).norm() < (m.V.row(best).transpose() - d).norm()) best = v;
  return best;
}

TEST(ConePlacement, TwoPolesBecomeFourSpreadCones) {
  const TriMesh m = test::icosphere(4);
  const EdgeTopology topo = edge_topology(m.F, m.num_vertices());
  const MatrixX3i TT = face_adjacency(topo);
  const TrivialConnection tc(m.V, m.F, topo, TT, 2);
  // Index 2 (a whole turn) at both poles: a vector field's singularities, which the half-turn
  // lattice cannot close around.
  std::vector<int> index(static_cast<size_t>(m.num_vertices()), 0);
  index[nearest_vertex(m, Vector3d::UnitZ())] = 2;
  index[nearest_vertex(m, -Vector3d::UnitZ())] = 2;
  ConePlacementReport report;
  const std::vector<int> placed =
      place_cones(tc, index, vertex_adjacency(m.F, m.num_vertices()), {}, &report);
  EXPECT_EQ(std::accumulate(placed.begin(), placed.end(), 0), 4);
  std::vector<int> cones;
  for (int v = 0; v < m.num_vertices(); ++v) {
    EXPECT_LE(std::abs(placed[v]), 1);
    if (placed[v]) cones.push_back(v);
  }
  ASSERT_EQ(cones.size(), 4u);
  EXPECT_EQ(report.split_poles, 2);
  EXPECT_LT(report.energy_after, 0.5 * report.energy_before);
  // Spread over the sphere (a regular tetrahedron's vertices are 1.63 apart on the unit sphere).
  double closest = 1e9;
  for (size_t i = 0; i < cones.size(); ++i)
    for (size_t j = i + 1; j < cones.size(); ++j)
      closest = std::min(closest, (m.V.row(cones[i]) - m.V.row(cones[j])).norm());
  std::printf("[ measure  ] poles split: E %.4f -> %.4f, closest cones %.2f apart\n",
              report.energy_before, report.energy_after, closest);
  EXPECT_GT(closest, 1.0);
}

TEST(ConePlacement, WellPlacedConesStay) {
  const TriMesh m = test::icosphere(3);
  const EdgeTopology topo = edge_topology(m.F, m.num_vertices());
  const MatrixX3i TT = face_adjacency(topo);
  const TrivialConnection tc(m.V, m.F, topo, TT, 2);
  std::vector<int> index(static_cast<size_t>(m.num_vertices()), 0);
  for (const Vector3d& d :
       {Vector3d(1, 1, 1), Vector3d(1, -1, -1), Vector3d(-1, 1, -1), Vector3d(-1, -1, 1)})
    index[nearest_vertex(m, d.normalized())] = 1;
  ConePlacementReport report;
  const std::vector<int> placed =
      place_cones(tc, index, vertex_adjacency(m.F, m.num_vertices()), {}, &report);
  // Already the tetrahedron: at most a step to a neighbour, and no worse.
  EXPECT_LE(report.energy_after, report.energy_before);
  for (int v = 0; v < m.num_vertices(); ++v)
    if (placed[v]) {
      double d = 1e9;
      for (int w = 0; w < m.num_vertices(); ++w)
        if (index[w]) d = std::min(d, (m.V.row(v) - m.V.row(w)).norm());
      EXPECT_LT(d, 0.3);
    }
}

// A torus needs no cone (its Euler characteristic is 0): a + cone outside and a - cone inside,
// where its curvature has those signs, are cancelled at little cost to E (each cone is a lattice
// defect: rings around it miss links); with a negative allowance they stay. (Pairs are cancelled
// one at a time: two + cones outside and two - inside stay, E 0.217 against 0.031 without them,
// as cancelling one pair alone raises E.)
TEST(ConePlacement, OppositeConesCancelInPairsWhereThatCostsLittleScale) {
  const TriMesh m = test::torus(4, 1, 64, 16);
  const EdgeTopology topo = edge_topology(m.F, m.num_vertices());
  const MatrixX3i TT = face_adjacency(topo);
  const TrivialConnection tc(m.V, m.F, topo, TT, 2);
  std::vector<int> index(static_cast<size_t>(m.num_vertices()), 0);
  index[nearest_vertex(m, Vector3d(5, 0, 0))] = 1;
  index[nearest_vertex(m, Vector3d(-3, 0, 0))] = -1;
  std::printf("[ measure  ] torus without cones: E %.4f\n",
              scale_energy(tc, tc.log_scale(std::vector<int>(index.size(), 0))));
  const Adjacency adj = vertex_adjacency(m.F, m.num_vertices());
  const auto cones = [](const std::vector<int>& placed) {
    return std::count_if(placed.begin(), placed.end(), [](int k) { return k != 0; });
  };
  ConePlacementOptions keep;
  keep.pair_allowance = -1;
  ConePlacementReport kept, cancelled;
  const std::vector<int> with_cones = place_cones(tc, index, adj, keep, &kept);
  const std::vector<int> without = place_cones(tc, index, adj, {}, &cancelled);
  std::printf("[ measure  ] torus: %ld cones kept, E %.4f; %ld after cancelling %d pairs, E %.4f\n",
              static_cast<long>(cones(with_cones)), kept.energy_after,
              static_cast<long>(cones(without)), cancelled.pairs_cancelled, cancelled.energy_after);
  EXPECT_EQ(cones(with_cones), 2);
  EXPECT_EQ(kept.pairs_cancelled, 0);
  EXPECT_EQ(cones(without), 0);
  EXPECT_EQ(cancelled.pairs_cancelled, 1);
  EXPECT_LE(cancelled.energy_after, kept.energy_after + ConePlacementOptions().pair_allowance);
  EXPECT_EQ(std::accumulate(without.begin(), without.end(), 0), 0);
}

}  // namespace
}  // namespace mq
