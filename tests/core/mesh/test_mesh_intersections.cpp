#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TriMesh transformed(TriMesh m, const Eigen::Matrix3d& R, const Vector3d& t) {
  for (int v = 0; v < m.num_vertices(); ++v) m.V.row(v) = (R * m.V.row(v).transpose() + t);
  return m;
}

// Four copies of a torus (radii 2 and 0.4), copy i turned about axis by i * angle and moved by
// i * step: tori through each other every which way, each copy's faces after the one before.
TriMesh four_tori(int around, int tube, double angle, const Vector3d& axis, const Vector3d& step) {
  const TriMesh a = test::torus(2.0, 0.4, around, tube);
  TriMesh all = a;
  for (int i = 1; i <= 3; ++i) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle * i, axis.normalized()).toRotationMatrix();
    append_mesh(all, transformed(a, R, i * step));
  }
  return all;
}

TEST(TriangleIntersection, BasicConfigurations) {
  const Vector3d a0(0, 0, 0), a1(1, 0, 0), a2(0, 1, 0);
  // Piercing.
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, {0.2, 0.2, -1}, {0.3, 0.2, 1}, {0.2, 0.3, 1}));
  // Above the plane.
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, {0, 0, 0.1}, {1, 0, 0.1}, {0, 1, 0.2}));
  // Crossing the plane outside the triangle.
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, {2, 2, -1}, {3, 2, 1}, {2, 3, 1}));
  // Touching at a vertex counts.
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, {1, 0, 0}, {2, 0, 1}, {2, 1, 1}));
  // Coplanar overlapping, coplanar disjoint, coplanar one inside the other.
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, {0.5, 0.5, 0}, {-0.5, 0.2, 0}, {0.3, -0.5, 0}));
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, {1, 1, 0}, {2, 1, 0}, {1, 2, 0}));
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, {0.1, 0.1, 0}, {0.2, 0.1, 0}, {0.1, 0.2, 0}));
  // Symmetric in its arguments.
  EXPECT_TRUE(triangles_intersect({0.1, 0.1, 0}, {0.2, 0.1, 0}, {0.1, 0.2, 0}, a0, a1, a2));
}

// meshes_intersect only looks at faces meeting the other mesh's box; it must agree with the
// full pairwise test on the two meshes put together, whatever the placement.
TEST(MeshIntersections, MeshesIntersectAgreesWithTheFullPairTest) {
  const TriMesh a = test::torus(2.0, 0.4, 32, 10);
  int hits = 0, misses = 0;
  for (int i = 0; i < 24; ++i) {
    const double angle = 0.37 * i, shift = 0.25 * i;
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(angle, Vector3d(1, 0.3, 0.1).normalized()).toRotationMatrix();
    const TriMesh b = transformed(a, R, Vector3d(shift, 0.1 * i, 0.05 * i));
    TriMesh both = a;
    append_mesh(both, b);
    IntersectionOptions between;
    between.between_components_only = true;
    const bool expected = !intersecting_face_pairs(both.V, both.F, between).empty();
    EXPECT_EQ(meshes_intersect(a, b), expected) << "placement " << i;
    EXPECT_EQ(meshes_intersect(b, a), expected) << "placement " << i;
    (expected ? hits : misses) += 1;
  }
  EXPECT_GT(hits, 0);
  EXPECT_GT(misses, 0);  // the placements reach beyond the torus: both answers are exercised
}

// The re-test after some faces moved: exactly the full test's pairs that hold an active face,
// for masks from none to all (both orders of a pair with one active face are reached).
TEST(MeshIntersections, PairsTouchingActiveFacesAreTheFullTestsFiltered) {
  const TriMesh both = four_tori(32, 10, 0.5, Vector3d(1, 0.3, 0.1), Vector3d(0.4, 0.1, 0.05));
  IntersectionOptions all;
  all.between_components_only = false;
  const auto full = intersecting_face_pairs(both.V, both.F, all);
  ASSERT_GT(full.size(), 100u);
  std::mt19937 rng(3);
  for (const double share : {0.0, 0.01, 0.2, 0.7, 1.0}) {
    std::vector<char> active(static_cast<size_t>(both.F.rows()));
    for (char& x : active) x = std::uniform_real_distribution<double>(0, 1)(rng) < share;
    std::vector<std::pair<int, int>> expected;
    for (const auto& [f, g] : full)
      if (active[f] || active[g]) expected.emplace_back(f, g);
    EXPECT_EQ(intersecting_face_pairs_touching(both.V, both.F, active), expected) << share;
  }
  EXPECT_THROW(intersecting_face_pairs_touching(both.V, both.F, std::vector<char>(3, 1)),
               InvalidInput);
}

// The grid's broad phase (float boxes rounded outward, each pair tested in one cell) misses no
// pair and reports none twice: the same pairs as testing every pair of faces, for tori placed
// every which way through each other and at scales where float rounding matters.
TEST(MeshIntersections, PairsAreThoseOfTestingEveryPair) {
  for (const double scale : {1.0, 1e-4, 3e5}) {
    TriMesh both = four_tori(24, 8, 0.9, Vector3d(0.2, 1, 0.4), Vector3d(0.7, -0.3, 0.2));
    both.V *= scale;
    both.V.array() += 7.0 * scale;  // away from the origin, where floats are coarser
    std::vector<int> part;
    connected_components(both.F, both.num_vertices(), part);
    std::vector<std::pair<int, int>> expected;
    const auto P = [&](int f, int k) -> Vector3d { return both.V.row(both.F(f, k)).transpose(); };
    for (int f = 0; f < both.num_faces(); ++f)
      for (int g = f + 1; g < both.num_faces(); ++g)
        if (part[f] != part[g] &&
            triangles_intersect(P(f, 0), P(f, 1), P(f, 2), P(g, 0), P(g, 1), P(g, 2)))
          expected.emplace_back(f, g);
    ASSERT_GT(expected.size(), 50u) << scale;
    IntersectionOptions between;
    between.between_components_only = true;
    EXPECT_EQ(intersecting_face_pairs(both.V, both.F, between), expected) << scale;
  }
}

// Labels in runs (each element's faces one after another, as in every output) are skipped per
// bucket by binary search; labels interleaved are filtered face by face. Both give the full
// test's pairs filtered by label, with or without an active set, for different and for same
// labels (two tori per label: the same-label pairs are those within a pair of tori).
TEST(MeshIntersections, LabelsInRunsOrInterleavedGiveTheFullTestsPairs) {
  const TriMesh both = four_tori(24, 8, 0.9, Vector3d(0.2, 1, 0.4), Vector3d(0.7, -0.3, 0.2));
  const int nf = both.num_faces();
  std::vector<int> perm(static_cast<size_t>(nf));  // shuffled face f is both's face perm[f]
  for (int f = 0; f < nf; ++f) perm[static_cast<size_t>(f)] = f;
  std::shuffle(perm.begin(), perm.end(), std::mt19937(5));
  TriMesh shuffled = both;
  for (int f = 0; f < nf; ++f) shuffled.F.row(f) = both.F.row(perm[static_cast<size_t>(f)]);
  IntersectionOptions all;
  all.between_components_only = false;
  const auto full = intersecting_face_pairs(both.V, both.F, all);
  std::mt19937 rng(7);
  for (const bool same : {false, true}) {
    for (const double share : {0.05, 1.0}) {
      std::vector<char> active(static_cast<size_t>(nf));
      for (char& x : active) x = std::uniform_real_distribution<double>(0, 1)(rng) < share;
      std::vector<int> label(static_cast<size_t>(nf));
      for (int f = 0; f < nf; ++f) label[static_cast<size_t>(f)] = f / (nf / 2);
      std::vector<std::pair<int, int>> expected;
      for (const auto& [f, g] : full)
        if ((active[f] || active[g]) && (label[f] == label[g]) == same) expected.emplace_back(f, g);
      ASSERT_GT(expected.size(), 5u) << same << " " << share;
      EXPECT_EQ(intersecting_face_pairs_touching(both.V, both.F, active, label, same), expected)
          << "labels in runs, same " << same << ", active share " << share;
      std::vector<char> active_s(static_cast<size_t>(nf));
      std::vector<int> label_s(static_cast<size_t>(nf));
      for (int f = 0; f < nf; ++f) {
        active_s[static_cast<size_t>(f)] = active[perm[static_cast<size_t>(f)]];
        label_s[static_cast<size_t>(f)] = label[perm[static_cast<size_t>(f)]];
      }
      std::vector<std::pair<int, int>> back;
      for (const auto& [f, g] :
           intersecting_face_pairs_touching(shuffled.V, shuffled.F, active_s, label_s, same)) {
        const int u = perm[static_cast<size_t>(f)], v = perm[static_cast<size_t>(g)];
        back.emplace_back(std::min(u, v), std::max(u, v));
      }
      std::sort(back.begin(), back.end());
      EXPECT_EQ(back, expected) << "labels interleaved, same " << same << ", share " << share;
    }
  }
}

TEST(MeshIntersections, LinkedToriDoNotIntersectOverlappingDo) {
  const TriMesh a = test::torus(2.0, 0.4, 48, 12);
  // A chain link: rotated into the xz plane and shifted by R along x, through a's hole.
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()).toRotationMatrix();
  const TriMesh linked = transformed(a, Rx, Vector3d(2.0, 0, 0));
  EXPECT_FALSE(meshes_intersect(a, linked));
  // Same orientation, overlapping in the plane: the tubes cross.
  const TriMesh overlapping = transformed(a, Eigen::Matrix3d::Identity(), Vector3d(2.0, 0, 0));
  EXPECT_TRUE(meshes_intersect(a, overlapping));
  // A linked torus pushed sideways so its tube cuts through a's tube.
  const TriMesh cutting = transformed(a, Rx, Vector3d(3.9, 0, 0));
  EXPECT_TRUE(meshes_intersect(a, cutting));

  TriMesh chain = a;
  append_mesh(chain, linked);
  EXPECT_TRUE(intersecting_face_pairs(chain.V, chain.F).empty());
  TriMesh clash = a;
  append_mesh(clash, overlapping);
  const auto pairs = intersecting_face_pairs(clash.V, clash.F);
  ASSERT_FALSE(pairs.empty());
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  for (const auto& [f, g] : pairs) {
    EXPECT_LT(f, a.num_faces());  // every pair joins the two tori
    EXPECT_GE(g, a.num_faces());
  }
}

TEST(MeshIntersections, ClosedMeshHasNoSelfIntersectionsAcrossSharedEdges) {
  // With all pairs tested, faces sharing an edge or a vertex must not be reported.
  const TriMesh t = test::torus(2.0, 0.5, 24, 12);
  IntersectionOptions all;
  all.between_components_only = false;
  EXPECT_TRUE(intersecting_face_pairs(t.V, t.F, all).empty());
  const TriMesh g = test::plane_grid(1.0, 1.0, 8, 8);  // flat: shared edges are coplanar
  EXPECT_TRUE(intersecting_face_pairs(g.V, g.F, all).empty());
}

TEST(MeshIntersections, SharedEdgeFoldAndCoplanarOverlapReported) {
  MatrixX3d V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0, 0.5, 0.5, 0;
  MatrixX3i F(2, 3);
  F << 0, 1, 2, 1, 0, 3;  // share edge 0-1, opposite sides: fine
  IntersectionOptions all;
  all.between_components_only = false;
  EXPECT_TRUE(intersecting_face_pairs(V, F, all).empty());
  F << 0, 1, 2, 1, 0, 4;  // vertex 4 folds back onto the first face
  const auto fold = intersecting_face_pairs(V, F, all);
  ASSERT_EQ(fold.size(), 1u);
  EXPECT_EQ(fold[0], std::make_pair(0, 1));

  // Two separate coplanar overlapping triangles (different components).
  MatrixX3d W(6, 3);
  W << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0, 1.2, 0.2, 0, 0.2, 1.2, 0;
  MatrixX3i G(2, 3);
  G << 0, 1, 2, 3, 4, 5;
  const auto pairs = intersecting_face_pairs(W, G);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], std::make_pair(0, 1));
}

TEST(MeshIntersections, SharedVertexPiercingReported) {
  // Two faces share vertex 0 and the second cuts through the first beyond it.
  MatrixX3d V(5, 3);
  V << 0, 0, 0, 2, 0, 0, 0, 2, 0, 1, 1, -1, 1, 1, 1;
  MatrixX3i F(2, 3);
  F << 0, 1, 2, 0, 3, 4;
  IntersectionOptions all;
  all.between_components_only = false;
  EXPECT_EQ(intersecting_face_pairs(V, F, all).size(), 1u);
  V.row(3) << -1, -1, -1;  // now the second face meets the first only at vertex 0
  V.row(4) << -1, -1, 1;
  EXPECT_TRUE(intersecting_face_pairs(V, F, all).empty());
}

// The fan that caps a thread's end lies in a tilted plane, so its corners are coplanar only up
// to rounding; sectors on opposite sides of the centre touch at the centre alone (the weave
// swatch's 12 threads were all reported as folded). A sector folded over its neighbour in the
// same plane is still a fold.
TEST(MeshIntersections, TiltedCapFanIsNotFolded) {
  const int n = 12;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()) *
                             Eigen::AngleAxisd(0.3, Vector3d::UnitX()))
                                .toRotationMatrix();
  MatrixX3d V(n + 1, 3);
  V.row(n) = Vector3d(6.070221, 0.570221, 0.322658).transpose();
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    V.row(i) = (V.row(n).transpose() + R * Vector3d(0.15 * std::cos(t), 0.15 * std::sin(t), 0))
                   .transpose();
  }
  MatrixX3i F(n, 3);
  for (int i = 0; i < n; ++i) F.row(i) << n, i, (i + 1) % n;
  EXPECT_TRUE(self_intersecting_components(V, F).empty());
  IntersectionOptions all;
  all.between_components_only = false;
  EXPECT_TRUE(intersecting_face_pairs(V, F, all).empty());
  // Sector 3 swung round to cover sectors 0-1: same plane, overlapping beyond the centre.
  F.row(3) << n, 0, 2;
  EXPECT_FALSE(intersecting_face_pairs(V, F, all).empty());
}

TEST(MeshIntersections, RealWeaveSwatchThreadsAreNotFolded) {
  const TriMesh weave = plain_weave();
  EXPECT_TRUE(self_intersecting_components(weave.V, weave.F).empty());
}

// A mesh of one component is tested without labels (the fold repair's per-ring test): the same
// verdicts as when the ring is one of several.
TEST(MeshIntersections, OneFoldedRingIsFoundAloneAndAmongOthers) {
  ChainMailOptions o;
  o.rows = 1;
  o.cols = 1;
  const TriMesh ring = chainmail_4in1(o);
  TriMesh folded = ring;
  // The wire's vertices on one side of the ring pushed through to the other side.
  for (Eigen::Index v = 0; v < folded.V.rows(); ++v)
    if (folded.V(v, 0) > 0.8) folded.V(v, 0) -= 1.8;
  TriMesh far = ring;
  far.V.col(1).array() += 10;
  EXPECT_TRUE(self_intersecting_components(ring.V, ring.F).empty());
  EXPECT_EQ(self_intersecting_components(folded.V, folded.F), std::vector<int>{0});
  TriMesh two = folded;
  append_mesh(two, far);
  EXPECT_EQ(self_intersecting_components(two.V, two.F), std::vector<int>{0});
  two = far;
  append_mesh(two, folded);
  EXPECT_EQ(self_intersecting_components(two.V, two.F), std::vector<int>{1});
  // self_intersects gives the same verdicts, and a pair that intersects as its witness; a
  // witness that no longer intersects (the ring unfolded again) does not decide.
  EXPECT_TRUE(self_intersects(two.V, two.F));
  EXPECT_FALSE(self_intersects(ring.V, ring.F));
  std::pair<int, int> witness{-1, -1};
  ASSERT_TRUE(self_intersects(folded.V, folded.F, &witness));
  ASSERT_LT(witness.first, witness.second);
  IntersectionOptions all;
  all.between_components_only = false;
  const auto pairs = intersecting_face_pairs(folded.V, folded.F, all);
  EXPECT_NE(std::find(pairs.begin(), pairs.end(), witness), pairs.end());
  EXPECT_TRUE(self_intersects(folded.V, folded.F, &witness));
  EXPECT_FALSE(self_intersects(ring.V, ring.F, &witness));
}

TEST(MeshIntersections, BadInputThrows) {
  MatrixX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  MatrixX3i F(1, 3);
  F << 0, 1, 3;
  EXPECT_THROW(intersecting_face_pairs(V, F), InvalidInput);
  F << 0, 1, 2;
  V(1, 1) = std::nan("");
  EXPECT_THROW(intersecting_face_pairs(V, F), InvalidInput);
}

}  // namespace
}  // namespace mq

namespace mq {
namespace {

TEST(MeshIntersections, RealChainMailRingsDoNotIntersect) {
  const TriMesh mail = read_mesh(test::shared_data("swatch/chainmail3d_48rings_49k.obj"));
  std::vector<int> fc;
  EXPECT_EQ(connected_components(mail.F, mail.num_vertices(), fc), 48);
  EXPECT_TRUE(intersecting_face_pairs(mail.V, mail.F).empty());
  // Sanity check that the test can fail on this mesh: shift one ring onto its neighbour.
  const auto groups = component_faces(fc, 48);
  TriMesh one = extract_faces(mail, groups[0]);
  TriMesh two = extract_faces(mail, groups[1]);
  const Vector3d shift = (two.V.colwise().mean() - one.V.colwise().mean()).transpose();
  one.V.rowwise() += shift.transpose();  // concentric rings of equal size must clash
  EXPECT_TRUE(meshes_intersect(one, two));
}

}  // namespace
}  // namespace mq
