// Ring unbending (core/shell/ring_unbending): a ring folded over an edge beyond the structure
// measure's limit hangs over it within the limit, out of the base, whole, with its links; a ring
// bent along the surface is left alone; the result does not depend on the thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/common/errors.h"
#include "core/mesh/linking_number.h"
#include "core/mesh/mesh_intersections.h"
#include "core/shell/ring_unbending.h"
#include "core/structure/texture_structure.h"
#include "tests/core/ring_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

constexpr double kHungWire = 0.15;
constexpr double kHungLift = 0.3;   // the flat ring's centre plane above the top face
constexpr double kHungRound = 0.2;  // the edge's rounding (test::over_edge)

// A block whose top face is z = 0 (x <= kHungRound) and side face x = kHungRound, meeting in
// the edge along y that test::over_edge rounds.
TriMesh edge_block() {
  TriMesh b = test::unit_cube();
  for (Eigen::Index v = 0; v < b.V.rows(); ++v)
    b.V.row(v) =
        Eigen::RowVector3d((8 + kHungRound) * b.V(v, 0) - 8, 8 * b.V(v, 1) - 4, 6 * b.V(v, 2) - 6);
  return b;
}

// The flat ring (centre radius 1, axis z) lying on the top face at x, its centre plane kHungLift
// up.
MatrixX3d hung_flat_ring(const TriMesh& torus, double x) {
  MatrixX3d V = torus.V;
  V.col(0).array() += x;
  V.col(2).array() += kHungLift;
  return V;
}

// The flat ring bent with the surface over the edge, at its own height, as a shell map bends it.
MatrixX3d bent_over_block_edge(const MatrixX3d& flat) {
  MatrixX3d V = flat;
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    V.row(v) = test::over_edge(flat.row(v).transpose(), kHungRound).transpose();
  return V;
}

double hung_fold(const MatrixX3d& V, const MatrixX3i& F) {
  return ring_fold(*ring_centre_loop(V, F));
}

struct HungScene {
  std::vector<TriMesh> rings;
  std::vector<MatrixX3d> flats;
  MatrixX3d V;
  std::vector<Eigen::Index> first{0};

  void add(const TriMesh& ring, const MatrixX3d& placed, const MatrixX3d& flat) {
    rings.push_back(ring);
    flats.push_back(flat);
    MatrixX3d all(V.rows() + placed.rows(), 3);
    all << V, placed;
    V = all;
    first.push_back(V.rows());
  }
  MatrixX3d element(size_t k) const { return V.middleRows(first[k], first[k + 1] - first[k]); }
  std::vector<char> unbend(const SignedHeight* ground, RingUnbendingStats* stats,
                           const std::vector<char>* candidates = nullptr) {
    std::vector<const MatrixX3i*> F;
    std::vector<const MatrixX3d*> flat;
    for (size_t k = 0; k < rings.size(); ++k) {
      F.push_back(&rings[k].F);
      flat.push_back(&flats[k]);
    }
    PlacementCheckOptions check;
    check.height = 2 * kHungLift;
    return unbend_folded_rings(V, first, F, flat, std::vector<char>(rings.size(), 0), ground, check,
                               {}, stats, candidates);
  }
};

TEST(RingUnbending, ARingFoldedOverAnEdgeHangsOverItWithinTheLimitAndOutOfTheBase) {
  const TriMesh base = edge_block();
  const SignedHeight ground(base.V, base.F);
  const TriMesh torus = test::torus(1.0, kHungWire, 48, 12);
  const MatrixX3d flat = hung_flat_ring(torus, 0.0);
  HungScene s;
  s.add(torus, bent_over_block_edge(flat), flat);
  const double before = hung_fold(s.element(0), torus.F) - hung_fold(flat, torus.F);
  ASSERT_GT(before, kFoldLimit);  // the measure would call it folded
  PlacementCheckOptions check;
  check.height = 2 * kHungLift;
  ASSERT_EQ(check_element_heights(ground, s.V, s.first, check)[0].below, 0);

  // The pass after the removal names its candidates: a folded ring not among them stays as it
  // is and is not counted; named, it is unbent.
  RingUnbendingStats stats;
  const MatrixX3d placed = s.V;
  const std::vector<char> none = {0}, named = {1};
  EXPECT_FALSE(s.unbend(&ground, &stats, &none)[0]);
  EXPECT_EQ(stats.folded, 0);
  EXPECT_EQ(s.V, placed);
  const std::vector<char> moved = s.unbend(&ground, &stats, &named);
  EXPECT_EQ(stats.folded, 1);
  EXPECT_EQ(stats.unbent, 1);
  ASSERT_TRUE(moved[0]);
  const MatrixX3d after = s.element(0);
  EXPECT_LE(hung_fold(after, torus.F) - hung_fold(flat, torus.F),
            RingUnbendingOptions{}.target_fold + 1e-9);
  EXPECT_EQ(check_element_heights(ground, s.V, s.first, check)[0].below, 0);
  EXPECT_TRUE(self_intersecting_components(after, torus.F).empty());
  // Still over the edge: its centre within a ring radius of it, the edge through its hole.
  const Vector3d centre = after.colwise().mean().transpose();
  EXPECT_LT(std::hypot(centre.x(), centre.z()), 1.0);
}

TEST(RingUnbending, ARingBentAlongTheSurfaceIsLeftAsItIs) {
  const TriMesh base = edge_block();
  const SignedHeight ground(base.V, base.F);
  const TriMesh torus = test::torus(1.0, kHungWire, 48, 12);
  // Wrapped round a cylinder of 6 ring radii on the top face, well away from the edge: bent
  // about 10 degrees, a sixth of the limit.
  const MatrixX3d flat = hung_flat_ring(torus, -2.0);
  MatrixX3d bent = flat;
  for (Eigen::Index v = 0; v < bent.rows(); ++v)
    bent.row(v) =
        (test::over_cylinder(flat.row(v).transpose() + Vector3d(2, 0, 0), 6.0) - Vector3d(2, 0, 0))
            .transpose();
  HungScene s;
  s.add(torus, bent, flat);
  const MatrixX3d before = s.V;
  RingUnbendingStats stats;
  const std::vector<char> moved = s.unbend(&ground, &stats);
  EXPECT_FALSE(moved[0]);
  EXPECT_EQ(stats.folded, 0);
  EXPECT_EQ(s.V, before);
}

// A folded ring with a ring through its hole on the top face, and a second folded ring beside
// it: every pair's linking number is as before, whatever moved; the same bytes on 1 and 2
// threads.
TEST(RingUnbending, LinksAreKeptAndTheResultIsTheSameOnAnyThreadCount) {
  const TriMesh base = edge_block();
  const SignedHeight ground(base.V, base.F);
  const TriMesh torus = test::torus(1.0, kHungWire, 48, 12);
  HungScene s;
  const MatrixX3d flat = hung_flat_ring(torus, 0.0);
  s.add(torus, bent_over_block_edge(flat), flat);
  // Upright through the first one's wire on the top face (x = -1), its axis along y.
  MatrixX3d upright = torus.V;
  for (Eigen::Index v = 0; v < upright.rows(); ++v)
    upright.row(v) =
        Eigen::RowVector3d(torus.V(v, 0) - 1.0, torus.V(v, 2), torus.V(v, 1) + kHungLift);
  s.add(torus, upright, upright);
  MatrixX3d beside = flat;
  beside.col(1).array() += 2.6;
  s.add(torus, bent_over_block_edge(beside), beside);
  const int linked = linking_number(*ring_centre_loop(s.element(0), torus.F),
                                    *ring_centre_loop(s.element(1), torus.F));
  ASSERT_EQ(std::abs(linked), 1);

  std::vector<MatrixX3d> results;
  for (const int threads : {1, 2}) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    HungScene t = s;
    RingUnbendingStats stats;
    t.unbend(&ground, &stats);
    EXPECT_EQ(stats.folded, 2);
    EXPECT_GE(stats.unbent, 1);  // something moved: the links were at stake
    for (size_t a = 0; a < 3; ++a)
      for (size_t b = a + 1; b < 3; ++b)
        EXPECT_EQ(linking_number(*ring_centre_loop(t.element(a), torus.F),
                                 *ring_centre_loop(t.element(b), torus.F)),
                  linking_number(*ring_centre_loop(s.element(a), torus.F),
                                 *ring_centre_loop(s.element(b), torus.F)))
            << a << " " << b;
    results.push_back(t.V);
  }
  EXPECT_EQ(results[0], results[1]);
}

// A hung ring makes no new link and keeps the share asked of its old ones.
TEST(RingUnbending, AHungRingKeepsHalfItsLinksAndMakesNone) {
  EXPECT_TRUE(hung_links_hold({1, -1, 1, 1, 0}, {1, -1, 1, 1, 0}, 1.0));
  EXPECT_TRUE(hung_links_hold({1, -1, 1, 1, 0}, {1, 1, 0, 0, 0}, 0.5));  // a flipped sign links
  EXPECT_FALSE(hung_links_hold({1, -1, 1, 1, 0}, {1, 0, 0, 0, 0}, 0.5));
  EXPECT_FALSE(hung_links_hold({1, -1, 1, 1, 0}, {1, -1, 1, 0, 0}, 1.0));
  EXPECT_FALSE(hung_links_hold({1, -1, 1, 1, 0}, {1, -1, 1, 1, 1}, 0.5));  // a new link
  EXPECT_TRUE(hung_links_hold({0, 0}, {0, 0}, 0.5));                       // nothing to keep
  EXPECT_THROW(hung_links_hold({1}, {1, 0}, 0.5), InvalidInput);
}

TEST(RingUnbending, SizesThatDisagreeAndBadOptionsAreRefused) {
  const TriMesh torus = test::torus(1.0, kHungWire, 24, 8);
  MatrixX3d V = torus.V;
  const std::vector<const MatrixX3i*> F = {&torus.F};
  const std::vector<const MatrixX3d*> flat = {&torus.V};
  const PlacementCheckOptions check;
  EXPECT_THROW(unbend_folded_rings(V, {0, V.rows() + 1}, F, flat, {0}, nullptr, check),
               InvalidInput);
  EXPECT_THROW(unbend_folded_rings(V, {0, V.rows()}, F, flat, {0, 0}, nullptr, check),
               InvalidInput);
  const std::vector<char> two_candidates = {1, 1};
  EXPECT_THROW(unbend_folded_rings(V, {0, V.rows()}, F, flat, {0}, nullptr, check, {}, nullptr,
                                   &two_candidates),
               InvalidInput);
  RingUnbendingOptions bad;
  bad.keep = {1.0};
  EXPECT_THROW(unbend_folded_rings(V, {0, V.rows()}, F, flat, {0}, nullptr, check, bad),
               InvalidInput);
  bad = {};
  bad.target_fold = 0;
  EXPECT_THROW(bad.validate(), InvalidInput);
  bad = {};
  bad.kept_links = 1.5;
  EXPECT_THROW(bad.validate(), InvalidInput);
}

}  // namespace
}  // namespace mq
