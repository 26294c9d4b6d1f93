#include <gtest/gtest.h>

#include <numeric>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"
#include "core/surface/line_field.h"
#include "core/surface/tangent_field.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

struct Fixture {
  TriMesh mesh;
  EdgeTopology topo;
  MatrixX3i TT;
  explicit Fixture(TriMesh m) : mesh(std::move(m)) {
    topo = edge_topology(mesh.F, mesh.num_vertices());
    TT = face_adjacency(topo);
  }
  DirectionField field(const MatrixX3d& guidance, int N, double weight) const {
    LineFieldOptions o;
    o.N = N;
    o.guidance_weight = weight;
    return smooth_direction_field(mesh.V, mesh.F, topo, TT, guidance, o);
  }
};

int index_sum(const DirectionField& f) {
  return std::accumulate(f.index.begin(), f.index.end(), 0);
}

TEST(LineField, FlatGridFollowsItsGuidanceWithoutSingularities) {
  const Fixture fx(test::plane_grid(4, 3, 12, 9));
  const MatrixX3d guide = tangent_field_from_direction(fx.mesh.V, fx.mesh.F, Vector3d(1, 0.5, 0));
  const DirectionField f = fx.field(guide, 2, 1.0);
  EXPECT_EQ(index_sum(f), 0);
  for (const int i : f.index) EXPECT_EQ(i, 0);
  const Vector3d want = Vector3d(1, 0.5, 0).normalized();
  for (int k = 0; k < f.direction.rows(); ++k)
    EXPECT_NEAR(std::abs(f.direction.row(k).dot(want)), 1.0, 1e-6) << "face " << k;
  for (const int m : f.matching) EXPECT_EQ(m, 0);
}

// Poincare-Hopf: the indices of a field on a closed surface sum to its Euler characteristic.
TEST(LineField, IndicesSumToTheEulerCharacteristic) {
  const Fixture sphere(test::icosphere(4));
  const MatrixX3d guide = smooth_tangent_field(sphere.mesh.V, sphere.mesh.F);
  for (const int N : {1, 2}) {
    const DirectionField f = sphere.field(guide, N, 1e-3);
    EXPECT_EQ(index_sum(f), 2 * N) << "sphere, N = " << N;
    for (const int m : f.matching) EXPECT_TRUE(m >= 0 && m < N);
  }
  // With weak guidance the line field's two poles split into four half-turn cones.
  const DirectionField line = sphere.field(guide, 2, 1e-3);
  int half = 0;
  for (const int i : line.index) half += (i == 1);
  EXPECT_EQ(half, 4);
  const Fixture torus(test::torus(2.0, 0.7, 48, 16));
  const DirectionField t = torus.field(smooth_tangent_field(torus.mesh.V, torus.mesh.F), 2, 1e-3);
  EXPECT_EQ(index_sum(t), 0);
}

TEST(LineField, MatchingOfAGivenFieldIsFoundAgain) {
  // A line field flipped on half of the faces (the same lines) has a half turn across the
  // edges between the halves, and the same (zero) indices.
  const Fixture fx(test::plane_grid(2, 2, 8, 8));
  MatrixX3d d = tangent_field_from_direction(fx.mesh.V, fx.mesh.F, Vector3d::UnitX());
  for (int f = 0; f < d.rows(); f += 2) d.row(f) *= -1;
  const DirectionField f = direction_field_matching(fx.mesh.V, fx.mesh.F, fx.topo, d, 2);
  int flips = 0;
  for (int e = 0; e < fx.topo.num_edges(); ++e) flips += f.matching[e];
  EXPECT_GT(flips, 0);
  for (const int i : f.index) EXPECT_EQ(i, 0);
  EXPECT_THROW(direction_field_matching(fx.mesh.V, fx.mesh.F, fx.topo, d, 5), InvalidInput);
}

// A + and a - half-turn cone at the two ends of one edge of a flat grid (the field turns
// half as fast as the angle about the one and against the angle about the other): the pair is
// cancelled, the directions stay, and only that edge's matching changes.
TEST(LineField, AdjacentOppositeConesCancel) {
  const Fixture fx(test::plane_grid(2, 2, 10, 10));
  const int p = 5 * 11 + 5, q = p + 1;  // the middle vertex and its neighbour along x
  const Vector3d cp = fx.mesh.V.row(p).transpose(), cq = fx.mesh.V.row(q).transpose();
  MatrixX3d d(fx.mesh.num_faces(), 3);
  for (int f = 0; f < fx.mesh.num_faces(); ++f) {
    Vector3d c = Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += fx.mesh.V.row(fx.mesh.F(f, k)).transpose() / 3;
    const double theta = 0.5 * std::atan2(c.y() - cp.y(), c.x() - cp.x()) -
                         0.5 * std::atan2(c.y() - cq.y(), c.x() - cq.x());
    d.row(f) << std::cos(theta), std::sin(theta), 0;
  }
  DirectionField f = direction_field_matching(fx.mesh.V, fx.mesh.F, fx.topo, d, 2);
  ASSERT_EQ(f.index[p], 1);
  ASSERT_EQ(f.index[q], -1);
  int singular = 0;
  for (const int i : f.index) singular += i != 0;
  ASSERT_EQ(singular, 2);
  const DirectionField before = f;
  EXPECT_EQ(cancel_singular_pairs(fx.mesh.V, fx.mesh.F, fx.topo, f), 1);
  for (const int i : f.index) EXPECT_EQ(i, 0);
  EXPECT_EQ(f.direction, before.direction);
  int changed = 0;
  for (int e = 0; e < fx.topo.num_edges(); ++e)
    if (f.matching[e] != before.matching[e]) {
      ++changed;
      EXPECT_TRUE((fx.topo.E(e, 0) == p && fx.topo.E(e, 1) == q) ||
                  (fx.topo.E(e, 0) == q && fx.topo.E(e, 1) == p));
    }
  EXPECT_EQ(changed, 1);
  // Nothing left to cancel; a field without pairs is unchanged.
  EXPECT_EQ(cancel_singular_pairs(fx.mesh.V, fx.mesh.F, fx.topo, f), 0);
}

// The sphere's four cones are far apart: none cancelled.
TEST(LineField, DistantConesStay) {
  const Fixture sphere(test::icosphere(4));
  DirectionField f = sphere.field(smooth_tangent_field(sphere.mesh.V, sphere.mesh.F), 2, 1e-3);
  EXPECT_EQ(cancel_singular_pairs(sphere.mesh.V, sphere.mesh.F, sphere.topo, f), 0);
  EXPECT_EQ(index_sum(f), 4);
}

}  // namespace
}  // namespace mq
