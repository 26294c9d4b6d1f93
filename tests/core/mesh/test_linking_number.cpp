#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/linking_number.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/quilt_elements.h"
#include "core/planar/swatch_generators.h"
#include "tests/core/ring_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

Loop circle(const Vector3d& centre, const Vector3d& u, const Vector3d& w, double radius, int n) {
  Loop l;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    l.push_back(centre + radius * (std::cos(a) * u + std::sin(a) * w));
  }
  return l;
}

Loop transformed(Loop l, const Eigen::Matrix3d& R, const Vector3d& t) {
  for (Vector3d& p : l) p = R * p + t;
  return l;
}

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  return q.normalized().toRotationMatrix();
}

TEST(LinkingNumber, HopfLinkIsPlusOrMinusOneAndUnlinkedIsZero) {
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  const Loop a = circle(Vector3d::Zero(), x, y, 1.0, 32);
  const Loop hopf = circle(Vector3d(1, 0, 0), x, z, 1.0, 32);  // through a's disk once
  EXPECT_EQ(std::abs(linking_number(a, hopf)), 1);
  EXPECT_EQ(linking_number(a, hopf), linking_number(hopf, a));  // symmetric
  // Reversing one loop flips the sign.
  Loop reversed(hopf.rbegin(), hopf.rend());
  EXPECT_EQ(linking_number(a, reversed), -linking_number(a, hopf));
  // Side by side, stacked, or with the boxes overlapping but not threaded: 0.
  EXPECT_EQ(linking_number(a, circle(Vector3d(3, 0, 0), x, z, 1.0, 32)), 0);
  EXPECT_EQ(linking_number(a, circle(Vector3d(0, 0, 0.3), x, y, 0.9, 32)), 0);
  EXPECT_EQ(linking_number(a, circle(Vector3d(0, 0, 0), x, z, 0.5, 32)), 0) << "inside the hole";
  EXPECT_EQ(linking_number(a, circle(Vector3d(2.05, 0, 0), x, z, 1.0, 32)), 0) << "just outside";
}

TEST(LinkingNumber, AgreesWithTheGaussIntegralUnderRandomRigidMotions) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> shift(-1.5, 1.5);
  const Loop a = circle(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(), 1.0, 24);
  int linked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Matrix3d R = random_rotation(rng);
    const Vector3d t(shift(rng), shift(rng), shift(rng));
    const Loop b =
        transformed(circle(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(), 0.8, 20), R, t);
    // Skip near-touching placements, where neither figure is meaningful.
    double gap = 1e9;
    for (const Vector3d& p : a)
      for (const Vector3d& q : b) gap = std::min(gap, (p - q).norm());
    if (gap < 0.05) continue;
    const double g = gauss_linking_integral(a, b);
    ASSERT_NEAR(g, std::round(g), 1e-6) << "trial " << trial;
    ASSERT_EQ(linking_number(a, b), static_cast<int>(std::lround(g))) << "trial " << trial;
    // The whole configuration moved rigidly keeps its linking number.
    const Eigen::Matrix3d S = random_rotation(rng);
    const Vector3d u(shift(rng), shift(rng), shift(rng));
    ASSERT_EQ(linking_number(transformed(a, S, u), transformed(b, S, u)), linking_number(a, b));
    if (linking_number(a, b) != 0) ++linked;
  }
  EXPECT_GT(linked, 20) << "the random placements must include linked ones";
}

TEST(LinkingNumber, DoubleWindingCountsTwo) {
  // A (2, 4) torus link component pair: b winds twice around a's core.
  const Loop a = circle(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(), 1.0, 48);
  Loop b;
  for (int k = 0; k < 96; ++k) {
    const double t = 2 * M_PI * k / 96;
    // A curve on the torus of radii (1, 0.3) going twice around the tube and once around
    // the axis: it links the core twice.
    const double u = t, v = 2 * t;
    b.emplace_back((1 + 0.3 * std::cos(v)) * std::cos(u), (1 + 0.3 * std::cos(v)) * std::sin(u),
                   0.3 * std::sin(v));
  }
  EXPECT_EQ(std::abs(linking_number(a, b)), 2);
  EXPECT_NEAR(std::abs(gauss_linking_integral(a, b)), 2.0, 1e-6);
}

TEST(LinkingNumber, ExactlyDegenerateGrazingFallsBackToTheIntegral) {
  // b's segment passes exactly through a's mean point and a cone edge: sign tests give 0.
  const Loop a = {Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(-1, 0, 0), Vector3d(0, -1, 0)};
  const Loop b = {Vector3d(0.5, 0, -1), Vector3d(0.5, 0, 1), Vector3d(3, 0, 1), Vector3d(3, 0, -1)};
  EXPECT_EQ(std::abs(linking_number(a, b)), 1);
}

TEST(RingCentreLoop, TorusGivesItsCoreCircle) {
  const TriMesh t = test::torus(2.0, 0.3, 40, 10);
  const auto loop = ring_centre_loop(t.V, t.F, 32);
  ASSERT_TRUE(loop.has_value());
  ASSERT_EQ(loop->size(), 32u);
  for (const Vector3d& p : *loop) {
    EXPECT_NEAR(std::hypot(p.x(), p.y()), 2.0, 0.05);
    EXPECT_NEAR(p.z(), 0.0, 1e-9);
  }
}

TEST(RingCentreLoop, CoarseRingGetsFewerBins) {
  const TriMesh t = test::torus(1.0, 0.12, 16, 4);
  const auto loop = ring_centre_loop(t.V, t.F, 32);
  ASSERT_TRUE(loop.has_value());
  EXPECT_EQ(loop->size(), 16u);
}

TEST(RingCentreLoop, RejectsWhatIsNotARing) {
  TriMesh cube = test::unit_cube();
  EXPECT_FALSE(ring_centre_loop(cube.V, cube.F).has_value()) << "genus 0";
  TriMesh grid = test::plane_grid(1, 1, 4, 4);
  EXPECT_FALSE(ring_centre_loop(grid.V, grid.F).has_value()) << "open";
  // Two tori sharing nothing: Euler characteristic 0 too, but each bin test passes only if
  // the vertices surround the mean point; two tori side by side do not.
  TriMesh a = test::torus(1.0, 0.2, 24, 8), b = a;
  b.V.col(0).array() += 5.0;
  append_mesh(a, b);
  EXPECT_FALSE(ring_centre_loop(a.V, a.F).has_value());
}

// The generated 4-in-1 sheet: ring (c, k) links (c +- 1, k) and (c +- 1, k +- 1 / 2) where they
// exist, nothing in its own column.
TEST(RingCentreLoop, FourInOneCellLinksItsDiagonalNeighbours) {
  for (const int detail : {0, 16}) {
    ChainMailOptions o;
    o.rows = 3;
    o.cols = 3;
    if (detail) o.ring_segments = 16, o.wire_segments = 4;
    const std::vector<Element> rings = split_elements(chainmail_4in1(o));
    ASSERT_EQ(rings.size(), 9u);
    std::vector<Loop> loops;
    for (const Element& e : rings) {
      const auto l = ring_centre_loop(e.V, e.F);
      ASSERT_TRUE(l.has_value());
      loops.push_back(*l);
    }
    // Column index and height (in ring pitches) of each ring from its loop's mean point.
    const double pitch = 1.25 * o.ring_radius;
    std::vector<Vector3d> centre;
    for (const Loop& l : loops) {
      Vector3d c = Vector3d::Zero();
      for (const Vector3d& p : l) c += p;
      centre.push_back(c / static_cast<double>(l.size()));
    }
    double x0 = 1e9;
    for (const Vector3d& c : centre) x0 = std::min(x0, c.x());
    int pairs = 0;
    for (size_t i = 0; i < loops.size(); ++i)
      for (size_t j = i + 1; j < loops.size(); ++j) {
        const bool linked = linking_number(loops[i], loops[j]) != 0;
        const long dc =
            std::lround((centre[i].x() - x0) / pitch) - std::lround((centre[j].x() - x0) / pitch);
        const double dy = std::abs(centre[i].y() - centre[j].y()) / pitch;
        const bool diagonal = std::abs(dc) == 1 && std::abs(dy - 0.5) < 0.05;
        EXPECT_EQ(linked, diagonal) << "detail " << detail << " rings " << i << ", " << j;
        pairs += linked;
      }
    EXPECT_EQ(pairs, 10) << "a 3 x 3 sheet has 10 linked pairs";
  }
}

RingShape shape_of(const TriMesh& ring) {
  const std::optional<Loop> loop = ring_centre_loop(ring.V, ring.F);
  EXPECT_TRUE(loop.has_value());
  return loop ? ring_shape(ring.V, ring.F, *loop) : RingShape{};
}

// A torus of centre radius 1 and wire 0.15: its wire 0.3 across, its free hole 2 (1 - 0.15) =
// 1.7 across, flat; so whatever its tessellation or placement.
TEST(RingShape, TorusHasItsWireItsHoleAndNoFold) {
  for (const auto& [n, m] : {std::pair<int, int>{48, 12}, {16, 4}}) {
    SCOPED_TRACE(testing::Message() << n << " x " << m);
    const TriMesh ring = test::torus(1.0, 0.15, n, m);
    const RingShape s = shape_of(ring);
    // The area of a polygonal tube is a little under 2 pi r L (a square section: 2 sqrt 2 / pi).
    EXPECT_NEAR(s.wire, 0.3, m == 4 ? 0.04 : 0.005);
    EXPECT_NEAR(s.opening, 1.7, 0.005);
    EXPECT_NEAR(s.fold, 0.0, 1e-9);
    std::mt19937_64 rng(3);
    const RingShape t =
        shape_of(test::mapped(ring, [&, R = random_rotation(rng)](const Vector3d& p) {
          return Vector3d(2.0 * (R * p) + Vector3d(1, -2, 3));
        }));
    EXPECT_NEAR(t.wire, 2 * s.wire, 1e-9);
    EXPECT_NEAR(t.opening, 2 * s.opening, 2e-3) << "the search stops at 1e-3 of the hole";
    EXPECT_NEAR(t.fold, 0.0, 1e-9);
  }
}

// Squeezed: a tube around an ellipse keeps its hole as wide as the ellipse's minor axis less the
// wire; a stadium pressed until its sides are 0.32 apart leaves a slit of 0.02 between walls
// of wire 0.15. The figure is the free disk between the projected edges, so a coarse ring's
// sections, a third of its radius apart, do not let it slip through the slit.
TEST(RingShape, SqueezedRingsOpeningFollowsItsWalls) {
  EXPECT_NEAR(shape_of(test::ellipse_ring(0.6, 0.15)).opening, 2 * (0.6 - 0.15), 0.01);
  EXPECT_NEAR(shape_of(test::stadium_ring(0.3, 0.15)).opening, 0.3, 0.005);
  EXPECT_NEAR(shape_of(test::stadium_ring(0.16, 0.15)).opening, 0.02, 0.015);
  // 16 sections: the walls touch along the sides, small pockets stay at the ends.
  const RingShape coarse = shape_of(test::stadium_ring(0.16, 0.15, 16, 4));
  EXPECT_LT(coarse.opening, 0.5 * coarse.wire);
  // Planar outlines, however squeezed, are not folded.
  EXPECT_NEAR(shape_of(test::stadium_ring(0.16, 0.15)).fold, 0.0, 1e-6);
}

// Bent: the angle between the halves' planes grows from a gentle cylinder to an edge.
TEST(RingShape, FoldIsTheTurnBetweenTheRingsHalves) {
  const TriMesh ring = test::torus(1.0, 0.15, 48, 12);
  const auto over_cylinder = [&](double rho) {
    return shape_of(
        test::mapped(ring, [rho](const Vector3d& p) { return test::over_cylinder(p, rho); }));
  };
  const auto over_edge = [&](double shift) {
    return shape_of(test::mapped(ring, [shift](const Vector3d& p) {
      return test::over_edge(p + Vector3d(shift, 0, 0), 0.2);
    }));
  };
  const double deg = M_PI / 180;
  EXPECT_LT(over_cylinder(10).fold, 8 * deg);
  EXPECT_NEAR(over_cylinder(2).fold, 29 * deg, 2 * deg);
  EXPECT_GT(over_cylinder(1).fold, over_cylinder(2).fold);
  EXPECT_NEAR(over_edge(0).fold, 75 * deg, 3 * deg) << "folded through its middle";
  EXPECT_LT(over_edge(0.7).fold, over_edge(0.5).fold) << "less of it beyond the edge";
  // The hole stays open when bent: folding is a cause of its own.
  EXPECT_GT(over_edge(0).opening, 3 * over_edge(0).wire);
}

TEST(RingShape, ShortLoopThrows) {
  const TriMesh ring = test::torus(1.0, 0.15, 16, 4);
  EXPECT_THROW(ring_shape(ring.V, ring.F, Loop(3, Vector3d::Zero())), InvalidInput);
  EXPECT_THROW(ring_fold(Loop(3, Vector3d::Zero())), InvalidInput);
}

// ring_fold is ring_shape's fold without the hole, to the bit.
TEST(RingShape, FoldAloneIsTheShapesFold) {
  const TriMesh ring = test::torus(1.0, 0.15, 48, 12);
  for (const double shift : {0.0, 0.4, 0.8}) {
    const TriMesh bent = test::mapped(ring, [shift](const Vector3d& p) {
      return test::over_edge(p + Vector3d(shift, 0, 0), 0.2);
    });
    const Loop loop = *ring_centre_loop(bent.V, bent.F);
    EXPECT_EQ(ring_fold(loop), ring_shape(bent.V, bent.F, loop).fold) << shift;
    EXPECT_GT(ring_fold(loop), 0.0);
  }
}

}  // namespace
}  // namespace mq
