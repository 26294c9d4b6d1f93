// Ring separation (core/shell/ring_separation): rings pressed into each other come apart by rigid
// motions, no pair's linking changes, obstacles and non-rings stay put, moves are bounded, and
// the result does not depend on the thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>

#include "core/common/errors.h"
#include "core/mesh/linking_number.h"
#include "core/mesh/mesh_intersections.h"
#include "core/shell/ring_separation.h"
#include "tests/test_support.h"

namespace mq {
namespace {

constexpr double kWire = 0.15;

// A ring of centre radius 1 and wire radius kWire, turned by R and moved to `at`.
TriMesh ring(const Eigen::Matrix3d& R, const Vector3d& at) {
  TriMesh t = test::torus(1.0, kWire, 48, 12);
  for (Eigen::Index v = 0; v < t.V.rows(); ++v)
    t.V.row(v) = (R * t.V.row(v).transpose() + at).transpose();
  return t;
}

Eigen::Matrix3d about_x(double angle) {
  return Eigen::AngleAxisd(angle, Vector3d::UnitX()).toRotationMatrix();
}

// Elements side by side in one vertex array, as the embedding holds them.
struct Scene {
  std::vector<TriMesh> rings;
  MatrixX3d V;
  std::vector<Eigen::Index> first{0};
  std::vector<std::optional<RingBins>> bins;

  void add(const TriMesh& m, bool is_ring = true) {
    rings.push_back(m);
    bins.push_back(is_ring ? ring_loop_bins(m.V, m.F) : std::nullopt);
    ASSERT_TRUE(!is_ring || bins.back().has_value());
    MatrixX3d all(V.rows() + m.V.rows(), 3);
    all << V, m.V;
    V = all;
    first.push_back(V.rows());
  }
  TriMesh element(size_t k) const {
    TriMesh m = rings[k];
    m.V = V.middleRows(first[k], first[k + 1] - first[k]);
    return m;
  }
  Loop loop(size_t k) const { return *ring_centre_loop(element(k).V, element(k).F); }
  // The loop by the binning the solver follows (point k stays point k as the ring moves).
  Loop tracked_loop(size_t k) const { return loop_from_bins(element(k).V, *bins[k]); }
  std::vector<char> separate(const std::vector<char>& movable, RingSeparationStats* stats,
                             const RingSeparationOptions& options = {}) {
    return separate_rings(V, first, bins, bins, movable, options, stats);
  }
};

TEST(RingSeparation, LinkedRingsPressedTogetherComeApartStillLinked) {
  Scene s;
  s.add(ring(Eigen::Matrix3d::Identity(), Vector3d::Zero()));
  // Through the first one's hole, 0.2 from its wire where the tubes need 0.3.
  s.add(ring(about_x(M_PI / 2), Vector3d(0.2, 0, 0)));
  ASSERT_TRUE(meshes_intersect(s.element(0), s.element(1)));
  ASSERT_EQ(std::abs(linking_number(s.loop(0), s.loop(1))), 1);
  RingSeparationStats stats;
  const std::vector<char> moved = s.separate({1, 1}, &stats);
  EXPECT_TRUE(moved[0] || moved[1]);
  EXPECT_EQ(stats.overlaps_before, 1);
  EXPECT_EQ(stats.overlaps_after, 0);
  EXPECT_EQ(stats.reverted, 0);
  EXPECT_FALSE(meshes_intersect(s.element(0), s.element(1)));
  EXPECT_EQ(std::abs(linking_number(s.loop(0), s.loop(1))), 1);
  // Rigid: every edge keeps its length.
  for (size_t k = 0; k < 2; ++k) {
    const TriMesh a = s.rings[k], b = s.element(k);
    for (int f = 0; f < a.num_faces(); ++f)
      EXPECT_NEAR((a.V.row(a.F(f, 0)) - a.V.row(a.F(f, 1))).norm(),
                  (b.V.row(b.F(f, 0)) - b.V.row(b.F(f, 1))).norm(), 1e-12);
  }
}

TEST(RingSeparation, UnlinkedRingsOverlappingComeApartUnlinked) {
  Scene s;
  s.add(ring(Eigen::Matrix3d::Identity(), Vector3d::Zero()));
  s.add(ring(Eigen::Matrix3d::Identity(), Vector3d(1.9, 0, 0.2)));  // stacked, 0.2 apart
  ASSERT_TRUE(meshes_intersect(s.element(0), s.element(1)));
  ASSERT_EQ(linking_number(s.loop(0), s.loop(1)), 0);
  RingSeparationStats stats;
  s.separate({1, 1}, &stats);
  EXPECT_FALSE(meshes_intersect(s.element(0), s.element(1)));
  EXPECT_EQ(linking_number(s.loop(0), s.loop(1)), 0);
}

TEST(RingSeparation, ObstaclesAndOtherElementsStayPut) {
  Scene s;
  s.add(ring(Eigen::Matrix3d::Identity(), Vector3d::Zero()));
  s.add(ring(about_x(M_PI / 2), Vector3d(0.2, 0, 0)));
  // Not a ring (a closed box, genus 0), overlapping the second: neither moved nor looked at.
  TriMesh box = test::unit_cube();
  box.V.array() *= 0.3;
  box.V.rowwise() += Vector3d(1.1, 0, 0.9).transpose();
  s.add(box, false);
  const MatrixX3d before = s.V;
  RingSeparationStats stats;
  const std::vector<char> moved = s.separate({0, 1, 1}, &stats);
  EXPECT_FALSE(moved[0]);
  EXPECT_TRUE(moved[1]);
  EXPECT_FALSE(moved[2]);
  EXPECT_EQ(stats.rings, 2);
  EXPECT_EQ(s.V.topRows(s.first[1]), before.topRows(s.first[1])) << "the obstacle moved";
  EXPECT_EQ(s.V.bottomRows(box.V.rows()), before.bottomRows(box.V.rows()));
  EXPECT_FALSE(meshes_intersect(s.element(0), s.element(1)));
}

// A chain of five rings, each through the next, pushed together along the chain: all come
// apart, every link kept, and no loop point travels beyond the bound.
Scene pressed_chain() {
  Scene s;
  for (int k = 0; k < 5; ++k) s.add(ring(about_x(k % 2 ? M_PI / 2 : 0), Vector3d(1.75 * k, 0, 0)));
  return s;
}

TEST(RingSeparation, APressedChainKeepsEveryLink) {
  Scene s = pressed_chain();
  std::vector<Loop> start;
  for (size_t k = 0; k < 5; ++k) start.push_back(s.tracked_loop(k));
  int touching = 0;
  for (size_t k = 0; k + 1 < 5; ++k) {
    ASSERT_EQ(std::abs(linking_number(s.loop(k), s.loop(k + 1))), 1);
    touching += meshes_intersect(s.element(k), s.element(k + 1));
  }
  ASSERT_GT(touching, 0);
  RingSeparationOptions o;
  RingSeparationStats stats;
  s.separate(std::vector<char>(5, 1), &stats, o);
  for (size_t k = 0; k < 5; ++k)
    for (size_t j = k + 1; j < 5; ++j) {
      EXPECT_FALSE(meshes_intersect(s.element(k), s.element(j))) << k << ", " << j;
      EXPECT_EQ(std::abs(linking_number(s.loop(k), s.loop(j))), j == k + 1 ? 1 : 0)
          << k << ", " << j;
    }
  for (size_t k = 0; k < 5; ++k) {
    const Loop now = s.tracked_loop(k);
    for (size_t i = 0; i < now.size(); ++i)
      EXPECT_LE((now[i] - start[k][i]).norm(), o.max_travel * kWire * 1.01) << "ring " << k;
  }
}

TEST(RingSeparation, SameBytesWhateverTheThreadCount) {
  std::vector<MatrixX3d> out;
  for (const int threads : {1, 2}) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Scene s = pressed_chain();
    s.separate(std::vector<char>(5, 1), nullptr);
    out.push_back(s.V);
  }
  EXPECT_EQ(out[0], out[1]);
}

TEST(RingSeparation, SizesThatDoNotAgreeAreRefused) {
  Scene s = pressed_chain();
  EXPECT_THROW(separate_rings(s.V, s.first, s.bins, s.bins, std::vector<char>(4, 1)), InvalidInput);
  std::vector<Eigen::Index> short_first(s.first.begin(), s.first.end() - 1);
  EXPECT_THROW(separate_rings(s.V, short_first, s.bins, s.bins, std::vector<char>(5, 1)),
               InvalidInput);
}

TEST(RingSeparation, OptionsOutOfRangeAreRefused) {
  RingSeparationOptions o;
  EXPECT_NO_THROW(o.validate());
  o.max_step = 0;
  EXPECT_THROW(o.validate(), InvalidInput);
  o = RingSeparationOptions{};
  o.max_iterations = -1;
  EXPECT_THROW(o.validate(), InvalidInput);
  o = RingSeparationOptions{};
  o.clearance = std::nan("");
  EXPECT_THROW(o.validate(), InvalidInput);
}

}  // namespace
}  // namespace mq
