// Linked versions (core/shell/linked_versions): a ring placed as an even copy takes the layout's
// version where that one threads more of its neighbours, and only where that version is still a
// ring (hole open, not folded) of about the copy's size; the copy is then the other version.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>

#include "core/common/errors.h"
#include "core/mesh/linking_number.h"
#include "core/shell/linked_versions.h"
#include "tests/core/ring_fixtures.h"

namespace mq {
namespace {

constexpr double kLinkWire = 0.15;

// A round ring of centre radius `radius` (all rings here share one face list: 48 x 12 sections).
TriMesh round_ring(double radius) {
  return test::planar_tube(
      [radius](double t) { return Vector2d(radius * std::cos(t), radius * std::sin(t)); },
      kLinkWire, 48, 12);
}

// m stood up in the xz plane (turned about x) and moved to `at`.
TriMesh upright_at(TriMesh m, const Vector3d& at) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()).toRotationMatrix();
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    m.V.row(v) = (R * m.V.row(v).transpose() + at).transpose();
  return m;
}

// Ring 0 lies flat at the origin with no other version; ring 1 is an even copy beside it,
// linked to nothing, whose layout version is `layout`.
struct TwoRings {
  SurfaceQuilt quilt;
  MatrixX3d V, A;
  std::vector<Eigen::Index> first, alternative_first;

  explicit TwoRings(const TriMesh& layout) {
    const TriMesh flat = round_ring(1.0), copy = upright_at(round_ring(1.0), {3.2, 0, 0});
    quilt.elements.resize(2);
    for (SurfaceElement& e : quilt.elements) e.F = flat.F;
    const Eigen::Index n = flat.V.rows();
    V.resize(2 * n, 3);
    V << flat.V, copy.V;
    A = layout.V;
    first = {0, n, 2 * n};
    alternative_first = {0, 0, n};
  }
  std::vector<char> choose(LinkedVersionStats* stats = nullptr) {
    return choose_linked_versions(quilt, first, V, A, alternative_first, {0, 0}, {}, stats);
  }
  Loop loop(Eigen::Index k) const {
    return *ring_centre_loop(V.middleRows(first[k], first[k + 1] - first[k]),
                             quilt.elements[static_cast<size_t>(k)].F);
  }
};

TEST(LinkedVersions, ACopyLinkedToNothingTakesTheLayoutsLinkedVersion) {
  const TriMesh linked = upright_at(round_ring(1.0), {1.0, 0, 0});
  TwoRings scene(linked);
  const MatrixX3d copy = scene.V.bottomRows(linked.V.rows());
  ASSERT_EQ(linking_number(scene.loop(0), scene.loop(1)), 0);
  LinkedVersionStats stats;
  EXPECT_EQ(scene.choose(&stats), (std::vector<char>{0, 1}));
  EXPECT_EQ(stats.candidates, 1);
  EXPECT_EQ(stats.chosen, 1);
  EXPECT_EQ(stats.links_gained, 1);
  EXPECT_NE(linking_number(scene.loop(0), scene.loop(1)), 0);
  EXPECT_TRUE(scene.V.bottomRows(linked.V.rows()).isApprox(linked.V));
  EXPECT_TRUE(scene.A.isApprox(copy));  // the copy is the other version now
}

TEST(LinkedVersions, AClosedOrOversizedLayoutVersionIsNotTaken) {
  // Linked, but squeezed until its hole closed (a stadium, its wire thicker than the gap between
  // its sides), about the copy's size.
  TriMesh closed = test::stadium_ring(0.1, kLinkWire, 48, 12);
  closed.V *= 2.0;  // its centre loop (by angle bins, shorter than the stadium) as the copy's
  closed = upright_at(closed, {1.3, 0, 0});
  // Linked, open, but 1.5 times the copy's size (the limit is 1.2).
  const TriMesh oversized = upright_at(round_ring(1.5), {1.5, 0, 0});
  for (const TriMesh& layout : {closed, oversized}) {
    TwoRings scene(layout);
    ASSERT_NE(linking_number(*ring_centre_loop(layout.V, layout.F), scene.loop(0)), 0);
    const MatrixX3d before = scene.V;
    LinkedVersionStats stats;
    EXPECT_EQ(scene.choose(&stats), (std::vector<char>{0, 0}));
    EXPECT_EQ(stats.chosen, 0);
    EXPECT_EQ(scene.V, before);
  }
  // Allowed 1.6 times the copy's size, the larger ring is taken.
  TwoRings scene(oversized);
  LinkedVersionOptions options;
  options.max_growth = 1.6;
  EXPECT_EQ(choose_linked_versions(scene.quilt, scene.first, scene.V, scene.A,
                                   scene.alternative_first, {0, 0}, options),
            (std::vector<char>{0, 1}));
}

TEST(LinkedVersions, SkippedRingsAndBadOptionsAndOffsets) {
  TwoRings scene(upright_at(round_ring(1.0), {1.0, 0, 0}));
  EXPECT_EQ(choose_linked_versions(scene.quilt, scene.first, scene.V, scene.A,
                                   scene.alternative_first, {0, 1}),
            (std::vector<char>{0, 0}));
  LinkedVersionOptions bad;
  bad.max_growth = 0.9;
  EXPECT_THROW(choose_linked_versions(scene.quilt, scene.first, scene.V, scene.A,
                                      scene.alternative_first, {0, 0}, bad),
               InvalidInput);
  std::vector<Eigen::Index> short_offsets = {0, 1};
  EXPECT_THROW(choose_linked_versions(scene.quilt, short_offsets, scene.V, scene.A,
                                      scene.alternative_first, {0, 0}),
               InvalidInput);
}

// Rings in a row, every other one an even copy moved off its place; each copy's layout version
// threads both neighbours. The same swaps whatever the thread count.
TEST(LinkedVersions, SameChoiceWhateverTheThreadCount) {
  const TriMesh flat = round_ring(1.0);
  const Eigen::Index n = flat.V.rows();
  const int rings = 9;
  SurfaceQuilt quilt;
  quilt.elements.resize(rings);
  MatrixX3d V(rings * n, 3), A(0, 3);
  std::vector<Eigen::Index> first{0}, alternative_first{0};
  for (int k = 0; k < rings; ++k) {
    quilt.elements[static_cast<size_t>(k)].F = flat.F;
    const Vector3d at(1.8 * k, 0, 0);
    if (k % 2) {
      // The odd rings lie flat, threading the upright even rings on either side.
      TriMesh lying = flat;
      lying.V.rowwise() += at.transpose();
      MatrixX3d grown(A.rows() + n, 3);
      grown << A, lying.V;
      A = grown;
      TriMesh away = lying;
      away.V.col(2).array() += 3.0;  // the copy: lifted clear of both
      V.middleRows(k * n, n) = away.V;
    } else {
      V.middleRows(k * n, n) = upright_at(flat, at).V;
    }
    first.push_back((k + 1) * n);
    alternative_first.push_back(A.rows());
  }
  std::vector<std::vector<char>> results;
  std::vector<MatrixX3d> outputs;
  for (const int threads : {1, 2, 4}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    MatrixX3d v = V, a = A;
    LinkedVersionStats stats;
    results.push_back(choose_linked_versions(quilt, first, v, a, alternative_first,
                                             std::vector<char>(rings, 0), {}, &stats));
    outputs.push_back(v);
    EXPECT_EQ(stats.chosen, rings / 2);
    EXPECT_EQ(stats.links_gained, 2 * (rings / 2));
  }
  for (size_t i = 1; i < results.size(); ++i) {
    EXPECT_EQ(results[i], results[0]);
    EXPECT_EQ(outputs[i], outputs[0]);
  }
}

}  // namespace
}  // namespace mq
