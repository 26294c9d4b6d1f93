#include <gtest/gtest.h>

#include <numeric>

#include "core/errors.h"
#include "core/line_field.h"
#include "core/mesh_topology.h"
#include "core/tangent_field.h"
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

}  // namespace
}  // namespace mq
