#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/common/errors.h"
#include "core/shell/placement_check.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// n small closed boxes (elements) of side 0.2 H over the top of the unit cube, the k-th with its
// bottom at height `bottom[k]` (in shell heights H = 0.1): 8 vertices each, in element order.
MatrixX3d boxes(const std::vector<double>& bottom, double H, std::vector<Eigen::Index>& first) {
  const TriMesh unit = test::unit_cube();
  MatrixX3d V(8 * static_cast<Eigen::Index>(bottom.size()), 3);
  first.assign(1, 0);
  for (size_t k = 0; k < bottom.size(); ++k) {
    for (int v = 0; v < 8; ++v) {
      const Vector3d c(0.1 + 0.1 * static_cast<double>(k), 0.5, 1 + bottom[k] * H);
      V.row(8 * static_cast<Eigen::Index>(k) + v) =
          (c + 0.2 * H * unit.V.row(v).transpose()).transpose();
    }
    first.push_back(first.back() + 8);
  }
  return V;
}

TEST(PlacementCheck, CountsVerticesUnderTheBaseAndAboveTheShell) {
  const TriMesh cube = test::unit_cube();
  const SignedHeight base(cube.V, cube.F);
  const double H = 0.1;
  std::vector<Eigen::Index> first;
  // In the shell; sunk by half its size; 1% under (allowed: the tolerance); above the shell.
  const MatrixX3d V = boxes({0.3, -0.1, -0.005, 0.95}, H, first);
  PlacementCheckOptions o;
  o.height = H;
  const std::vector<ElementHeights> h = check_element_heights(base, V, first, o);
  ASSERT_EQ(h.size(), 4u);
  EXPECT_EQ(h[0].below, 0);
  EXPECT_EQ(h[0].above, 0);
  EXPECT_EQ(h[1].below, 4);  // its bottom four corners
  EXPECT_NEAR(h[1].lowest, -0.1 * H, 1e-12);
  EXPECT_GE(h[1].lowest_vertex, first[1]);
  EXPECT_LT(h[1].lowest_vertex, first[2]);
  EXPECT_EQ(h[2].below, 0);
  EXPECT_EQ(h[3].above, 4);  // its top corners at 1.15 H
  const PlacementFigures f = placement_figures(h);
  EXPECT_EQ(f.vertices, 32);
  EXPECT_EQ(f.below, 4);
  EXPECT_EQ(f.above, 4);
  EXPECT_NEAR(f.lowest, -0.1 * H, 1e-12);
  // Only some elements.
  const std::vector<ElementHeights> some = check_element_heights(base, V, first, o, {0, 1, 0, 0});
  EXPECT_EQ(some[0].vertices, 0);
  EXPECT_EQ(some[1].below, 4);
  EXPECT_EQ(placement_figures(h, {1, 0, 1, 1}).below, 0);
}

TEST(PlacementCheck, VerticesNearAMeasuredOneNeedNoQuery) {
  // A dense element well inside the shell: most vertices lie in the empty ball of one measured.
  const TriMesh cube = test::unit_cube();
  const SignedHeight base(cube.V, cube.F);
  MatrixX3d V(1000, 3);
  for (int i = 0; i < 1000; ++i) {
    const int row = (i / 10) % 10, layer = i / 100;  // a 10 x 10 x 10 block of points
    V.row(i) << 0.5 + 0.002 * (i % 10), 0.5 + 0.002 * row, 1.05 + 0.002 * layer;
  }
  PlacementCheckOptions o;
  o.height = 0.1;
  const std::vector<ElementHeights> h = check_element_heights(base, V, {0, 1000}, o);
  EXPECT_EQ(h[0].vertices, 1000);
  EXPECT_EQ(h[0].below, 0);
  EXPECT_EQ(h[0].above, 0);
  EXPECT_LT(h[0].queries, 100);
}

TEST(PlacementCheck, SunkElementsAreLiftedOutWhole) {
  const TriMesh cube = test::unit_cube();
  const SignedHeight base(cube.V, cube.F);
  const double H = 0.1;
  std::vector<Eigen::Index> first;
  MatrixX3d V = boxes({0.3, -0.4, -0.1}, H, first);
  const MatrixX3d before = V;
  PlacementCheckOptions o;
  o.height = H;
  std::vector<char> moved;
  const std::vector<ElementHeights> h = lift_out_of_base(base, V, first, o, {1, 1, 1}, 4, &moved);
  EXPECT_EQ(moved, (std::vector<char>{0, 1, 1}));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(h[static_cast<size_t>(k)].below, 0) << k;
  // Moved rigidly (a translation), up to just above the base.
  const Vector3d shift = (V.row(8) - before.row(8)).transpose();
  for (Eigen::Index v = 8; v < 16; ++v)
    EXPECT_NEAR((V.row(v) - before.row(v) - shift.transpose()).norm(), 0, 1e-12);
  EXPECT_NEAR(shift.z(), 0.405 * H, 1e-12);
  EXPECT_TRUE(V.topRows(8) == before.topRows(8));
  EXPECT_THROW(lift_out_of_base(base, V, first, o, {1, 1, 1}, 0), InvalidInput);
}

TEST(PlacementCheck, IndependentOfThreadCountAndRejectsBadInput) {
  const TriMesh cube = test::unit_cube();
  const SignedHeight base(cube.V, cube.F);
  std::vector<Eigen::Index> first;
  std::vector<double> bottoms;
  for (int k = 0; k < 9; ++k) bottoms.push_back(-0.5 + 0.2 * k);
  const MatrixX3d V = boxes(bottoms, 0.1, first);
  PlacementCheckOptions o;
  o.height = 0.1;
  auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    const PlacementFigures f = placement_figures(check_element_heights(base, V, first, o));
    return std::make_tuple(f.vertices, f.below, f.above, f.lowest);
  };
  EXPECT_EQ(run(1), run(2));
  o.height = 0;
  EXPECT_THROW(check_element_heights(base, V, first, o), InvalidInput);
  o.height = 0.1;
  EXPECT_THROW(check_element_heights(base, V, {0, 5}, o), InvalidInput);
}

}  // namespace
}  // namespace mq
