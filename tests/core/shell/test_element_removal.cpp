#include <gtest/gtest.h>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/similarity_fit.h"
#include "core/shell/element_removal.h"
#include "core/shell/element_unfolding.h"
#include "core/shell/quilt_intersections.h"
#include "tests/core/ring_fixtures.h"

namespace mq {
namespace {

// Rings of centre radius 1 and wire radius 0.2 in the z = 0 plane (outer radius 1.2) centred at
// `centres`, as the embedding holds them: one matrix of vertices, element k's rows
// [first[k], first[k + 1]).
struct Rings {
  SurfaceQuilt quilt;
  std::vector<Eigen::Index> first{0};
  TriMesh all;
  std::vector<int> element_of;
};

Rings rings_at(const std::vector<Vector3d>& centres) {
  Rings r;
  const TriMesh ring = test::ellipse_ring(1.0, 0.2, 32, 8);
  for (const Vector3d& c : centres) {
    SurfaceElement e;
    e.F = ring.F;
    e.face.assign(static_cast<size_t>(ring.V.rows()), 0);
    r.quilt.elements.push_back(e);
    TriMesh moved = ring;
    moved.V.rowwise() += c.transpose();
    const Eigen::Index v0 = r.all.V.rows(), f0 = r.all.F.rows();
    r.all.V.conservativeResize(v0 + moved.V.rows(), 3);
    r.all.V.bottomRows(moved.V.rows()) = moved.V;
    r.all.F.conservativeResize(f0 + moved.F.rows(), 3);
    r.all.F.bottomRows(moved.F.rows()) = moved.F.array() + static_cast<int>(v0);
    r.element_of.insert(r.element_of.end(), static_cast<size_t>(moved.F.rows()),
                        static_cast<int>(r.quilt.elements.size() - 1));
    r.first.push_back(r.all.V.rows());
  }
  return r;
}

// A 4 x 3 grid of rings 2.35 apart (their tubes overlap by 0.05 where neighbours face each
// other); a few rings moved: the pairs kept up to date equal a full pass's.
TEST(QuiltIntersections, UpdatedPairsEqualAFullPass) {
  std::vector<Vector3d> centres;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j) centres.emplace_back(2.35 * i, 2.35 * j, 0);
  Rings r = rings_at(centres);
  const std::vector<std::pair<int, int>> before = all_face_pairs(r.all.V, r.all.F);
  ASSERT_FALSE(before.empty());
  std::vector<char> changed(centres.size(), 0);
  for (const int k : {1, 5, 10}) {
    changed[static_cast<size_t>(k)] = 1;
    r.all.V.middleRows(r.first[k], r.first[k + 1] - r.first[k]).rowwise() +=
        Eigen::RowVector3d(k == 5 ? 0.2 : -0.1, 0.03 * k, 0.01);
  }
  const std::vector<std::pair<int, int>> expected = all_face_pairs(r.all.V, r.all.F);
  EXPECT_NE(expected, before);
  EXPECT_EQ(updated_face_pairs(r.all.V, r.all.F, r.first, r.element_of, before, changed), expected);
  // Nothing changed: the pairs as they were.
  EXPECT_EQ(updated_face_pairs(r.all.V, r.all.F, r.first, r.element_of, expected,
                               std::vector<char>(centres.size(), 0)),
            expected);
}

TEST(ElementRemoval, FoldedElementsGoAndFewAsCanOfTouchingOnes) {
  // Element 0 folds (a pair of its own faces); element 1 touches 2 and 3, which do not touch
  // each other: 0 and 1 go.
  const std::vector<int> element_of = {0, 0, 1, 1, 2, 3};
  std::vector<char> drop(4, 0), folded(4, 0);
  choose_removals({{0, 1}, {2, 4}, {3, 5}}, element_of, drop, folded);
  EXPECT_EQ(drop, (std::vector<char>{1, 1, 0, 0}));
  EXPECT_EQ(folded, (std::vector<char>{1, 0, 0, 0}));
}

// Rings 0 and 1 overlap by 0.05 (centres 2.35 apart), ring 1 dropped: at 95% of its size it
// clears ring 0 and comes back; ring 2, pressed 0.9 into ring 0 from the other side, stays out.
TEST(ElementRemoval, ShrinkToFitKeepsARingThatClearsItsNeighbourSmaller) {
  Rings r = rings_at({Vector3d(0, 0, 0), Vector3d(2.35, 0, 0), Vector3d(-1.5, 0, 0)});
  std::vector<char> drop = {0, 1, 1};
  const MatrixX3d before = r.all.V;
  EXPECT_EQ(shrink_to_fit(r.quilt, r.first, std::vector<char>(3, 0), r.all.V, drop), 1);
  EXPECT_EQ(drop, (std::vector<char>{0, 0, 1}));
  const Eigen::Index v0 = r.first[1], n = r.first[2] - r.first[1];
  const Vector3d c = before.middleRows(v0, n).colwise().mean().transpose();
  EXPECT_NEAR((r.all.V.row(v0).transpose() - c).norm(),
              0.95 * (before.row(v0).transpose() - c).norm(), 1e-12);
  TriMesh ring0, ring1;
  ring0.V = before.middleRows(0, n);
  ring0.F = r.quilt.elements[0].F;
  ring1.V = r.all.V.middleRows(v0, n);
  ring1.F = r.quilt.elements[1].F;
  EXPECT_FALSE(meshes_intersect(ring0, ring1));
  // Elements to skip are not tried.
  Rings s = rings_at({Vector3d(0, 0, 0), Vector3d(2.35, 0, 0)});
  std::vector<char> drop2 = {0, 1};
  EXPECT_EQ(shrink_to_fit(s.quilt, s.first, {0, 1}, s.all.V, drop2), 0);
  EXPECT_EQ(drop2[1], 1);
}

// A dropped ring whose layout version clears its neighbours takes it; one whose version still
// meets a kept ring stays out.
TEST(ElementRemoval, ALayoutVersionThatClearsItsNeighboursIsTaken) {
  Rings r = rings_at({Vector3d(0, 0, 0), Vector3d(2.35, 0, 0), Vector3d(0, 2.35, 0)});
  const Eigen::Index n = r.first[1];
  MatrixX3d A(2 * n, 3);
  A.topRows(n) = r.all.V.middleRows(r.first[1], n).rowwise() + Eigen::RowVector3d(0.5, 0, 0);
  A.bottomRows(n) = r.all.V.middleRows(r.first[2], n).rowwise() + Eigen::RowVector3d(0, -0.5, 0);
  const std::vector<Eigen::Index> alternative_first = {0, 0, n, 2 * n};
  std::vector<char> drop = {0, 1, 1};
  const std::vector<char> back = try_layout_versions(r.quilt, r.first, std::vector<char>(3, 0), A,
                                                     alternative_first, r.all.V, drop);
  EXPECT_EQ(back, (std::vector<char>{0, 1, 0}));
  EXPECT_EQ(drop, (std::vector<char>{0, 0, 1}));
  EXPECT_EQ(r.all.V.middleRows(r.first[1], n), A.topRows(n));
}

// A ring whose right half the map folded back over its left half intersects itself; unfolded,
// it does not. A ring placed unfolded (scaled and turned) keeps nearly its placed shape.
TEST(ElementUnfolding, AFoldedRingComesOutWholeAndAnUnfoldedOneStays) {
  const TriMesh flat = test::ellipse_ring(1.0, 0.2, 32, 8);
  MatrixX3d folded = flat.V;
  for (Eigen::Index v = 0; v < folded.rows(); ++v)
    if (folded(v, 0) > 0) folded.row(v) << -0.8 * folded(v, 0), folded(v, 1), folded(v, 2) + 0.05;
  ASSERT_FALSE(self_intersecting_components(folded, flat.F).empty());
  const PlacementCheckOptions check{0.5, 0.01};
  const MatrixX3d repaired = unfold_element(folded, flat.V, flat.F, nullptr, check);
  EXPECT_TRUE(self_intersecting_components(repaired, flat.F).empty());

  MatrixX3d placed = 2.0 * flat.V;
  placed.col(2) += placed.col(0) * 0.3;
  placed.rowwise() += Eigen::RowVector3d(1, 2, 3);
  // Not folded: the first blend, 95% of the placed shape and 5% of the fitted flat one.
  const MatrixX3d expected = 0.95 * placed + 0.05 * similarity_fit(flat.V, placed);
  EXPECT_LT(
      (unfold_element(placed, flat.V, flat.F, nullptr, check) - expected).cwiseAbs().maxCoeff(),
      1e-12);
}

}  // namespace
}  // namespace mq
