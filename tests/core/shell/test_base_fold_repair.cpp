#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"
#include "core/shell/base_fold_repair.h"
#include "core/shell/offset_surface.h"
#include "core/shell/signed_height.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// A flat 1 x 1 grid of 10 x 10 squares with its middle vertex pushed `by` along x: past its
// neighbour (0.1 away) its star folds over itself.
TriMesh pushed_grid(double by, int* vertex = nullptr) {
  TriMesh g = test::plane_grid(1, 1, 10, 10);
  int middle = -1;
  for (int v = 0; v < g.num_vertices(); ++v)
    if ((g.V.row(v) - Vector3d(0.5, 0.5, 0).transpose()).norm() < 1e-9) middle = v;
  g.V(middle, 0) += by;
  if (vertex) *vertex = middle;
  return g;
}

TEST(BaseFoldRepair, UnboundedRepairUndoesAFold) {
  const TriMesh g = pushed_grid(0.15);
  ASSERT_FALSE(folded_faces(g.V, g.F).empty());
  const FoldRepair r = repair_folds(g.V, g.F);
  EXPECT_TRUE(r.unrepaired_faces.empty());
  EXPECT_TRUE(folded_faces(r.V, g.F).empty());
  EXPECT_FALSE(r.moved_vertices.empty());
}

TEST(BaseFoldRepair, BoundedRepairStaysOnTheBaseAndReportsWhatItCannotUndo) {
  // A bump with a fold on its slope, so that relaxing moves vertices off the surface: the
  // bounds hold them within 0.001 above and 0.0001 under it, and 0.02 from where they were.
  TriMesh g = pushed_grid(0.15);
  for (int v = 0; v < g.num_vertices(); ++v)
    g.V(v, 2) = 0.2 * std::exp(-10 * (std::pow(g.V(v, 0) - 0.5, 2) + std::pow(g.V(v, 1) - 0.5, 2)));
  FoldRepairOptions o;
  o.max_above = 0.001;
  o.max_below = 0.0001;
  o.max_shift = 0.02;
  const FoldRepair r = repair_folds(g.V, g.F, o);
  // The fold is 0.05 past the neighbour: 0.02 of sliding cannot undo it.
  EXPECT_FALSE(r.unrepaired_faces.empty());
  EXPECT_FALSE(r.moved_vertices.empty());
  const SignedHeight h(g.V, g.F);
  for (const int v : r.moved_vertices) {
    const double s = h(Vector3d(r.V.row(v).transpose()));
    EXPECT_LE(s, o.max_above + 1e-12) << v;
    EXPECT_GE(s, -o.max_below - 1e-12) << v;
    EXPECT_LE((r.V.row(v) - g.V.row(v)).norm(), o.max_shift + 1e-12) << v;
  }
  EXPECT_LE(r.max_above, o.max_above + 1e-12);
  EXPECT_LE(r.max_below, o.max_below + 1e-12);
  // Allowed to slide far enough, the same repair undoes it.
  o.max_shift = 0.2;
  EXPECT_TRUE(repair_folds(g.V, g.F, o).unrepaired_faces.empty());
}

TEST(BaseFoldRepair, OffsetCriterionRelaxesOnlyWhatKeepsTheShellOut) {
  // cup_mug_11k folds near its handle (vertex 5099 has no direction above all its faces); by
  // offset_surface's test only the vertices there are relaxed, fewer than for folded_faces.
  const TriMesh cup = read_mesh(test::shared_data("base/cup_mug_11k.off"));
  const std::vector<int> before = fold_vertices(cup.V, cup.F);
  EXPECT_TRUE(std::binary_search(before.begin(), before.end(), 5099));
  FoldRepairOptions o;
  o.offset_criterion = true;
  const FoldRepair by_offset = repair_folds(cup.V, cup.F, o);
  EXPECT_TRUE(by_offset.unrepaired_faces.empty());
  EXPECT_TRUE(fold_vertices(by_offset.V, cup.F).empty());
  const FoldRepair by_faces = repair_folds(cup.V, cup.F);
  EXPECT_FALSE(by_offset.moved_vertices.empty());
  EXPECT_LT(by_offset.moved_vertices.size(), by_faces.moved_vertices.size());
  // A fold_vertices-free base is left alone.
  const TriMesh g = test::plane_grid(1, 1, 4, 4);
  EXPECT_TRUE(repair_folds(g.V, g.F, o).moved_vertices.empty());
}

TEST(BaseFoldRepair, UnfoldedBaseIsLeftAloneAndBadOptionsThrow) {
  const TriMesh g = test::plane_grid(1, 1, 4, 4);
  const FoldRepair r = repair_folds(g.V, g.F);
  EXPECT_TRUE(r.folded_faces.empty());
  EXPECT_TRUE(r.moved_vertices.empty());
  EXPECT_TRUE(r.V == g.V);
  FoldRepairOptions o;
  o.max_shift = -1;
  EXPECT_THROW(repair_folds(g.V, g.F, o), InvalidInput);
  o = FoldRepairOptions();
  o.max_rounds = 0;
  EXPECT_THROW(repair_folds(g.V, g.F, o), InvalidInput);
}

}  // namespace
}  // namespace mq
