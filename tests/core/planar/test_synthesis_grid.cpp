// The synthesis grid of paper section 2.3 (seed rule, face assignment) and the overlapping
// region of section 2.5 built on it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/common/errors.h"
#include "core/planar/overlap_region.h"
#include "core/planar/synthesis_grid.h"

namespace mq {
namespace {

// Processed 8-neighbours of c, counted independently of the implementation.
int processed_neighbours(const SynthesisGrid& g, const Cell& c) {
  int n = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const Cell d{c.x + dx, c.y + dy};
      if ((dx || dy) && g.contains(d) && g.processed(d)) ++n;
    }
  return n;
}

TEST(SynthesisGrid, EmptyGridSeedsTheFirstCell) {
  const SynthesisGrid g(Vector2d(0, 0), 1.0, 5, 4);
  Cell seed{-1, -1};
  ASSERT_TRUE(g.next_seed(seed));
  EXPECT_EQ(seed, (Cell{0, 0}));
}

TEST(SynthesisGrid, SeedHasTheMostProcessedNeighbours) {
  SynthesisGrid g(Vector2d(0, 0), 1.0, 6, 6);
  // A processed row segment: (1, 1) touches all three cells, (0, 1) and (2, 1) only two.
  for (int x = 0; x < 3; ++x) g.set_processed({x, 0});
  Cell seed;
  ASSERT_TRUE(g.next_seed(seed));
  EXPECT_EQ(seed, (Cell{1, 1}));
  EXPECT_EQ(processed_neighbours(g, seed), 3);
  // An L of five cells: its inner corner (1, 1) has 5 processed neighbours.
  SynthesisGrid h(Vector2d(0, 0), 1.0, 6, 6);
  for (int x = 0; x < 3; ++x) h.set_processed({x, 0});
  for (int y = 1; y < 3; ++y) h.set_processed({0, y});
  ASSERT_TRUE(h.next_seed(seed));
  EXPECT_EQ(seed, (Cell{1, 1}));
  EXPECT_EQ(processed_neighbours(h, seed), 5);
}

TEST(SynthesisGrid, TiesGoToTheLowestIndex) {
  SynthesisGrid g(Vector2d(0, 0), 1.0, 6, 6);
  g.set_processed({4, 4});
  g.set_processed({1, 3});
  // Many cells have one processed neighbour; the lowest (y, x) index among them is (0, 2).
  Cell seed;
  ASSERT_TRUE(g.next_seed(seed));
  EXPECT_EQ(seed, (Cell{0, 2}));
}

TEST(SynthesisGrid, SeedRuleHoldsOnRandomPatterns) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    SynthesisGrid g(Vector2d(0, 0), 0.5, 7, 5);
    for (int i = 0; i < g.num_cells(); ++i)
      if (rng() % 3 == 0) g.set_processed(g.cell(i));
    Cell seed;
    if (!g.next_seed(seed)) {
      EXPECT_EQ(g.num_processed(), g.num_cells());
      continue;
    }
    ASSERT_TRUE(g.contains(seed));
    EXPECT_FALSE(g.processed(seed));
    const int best = processed_neighbours(g, seed);
    for (int i = 0; i < g.num_cells(); ++i) {
      const Cell c = g.cell(i);
      if (g.processed(c)) continue;
      const int n = processed_neighbours(g, c);
      EXPECT_LE(n, best) << "trial " << trial << " cell " << c.x << "," << c.y;
      if (n == best) {
        EXPECT_GE(i, g.index(seed)) << "trial " << trial;
      }
    }
  }
}

TEST(SynthesisGrid, FullGridHasNoSeed) {
  SynthesisGrid g(Vector2d(0, 0), 1.0, 3, 2);
  for (int i = 0; i < g.num_cells(); ++i) g.set_processed(g.cell(i));
  EXPECT_EQ(g.num_processed(), 6);
  Cell seed;
  EXPECT_FALSE(g.next_seed(seed));
}

TEST(SynthesisGrid, CellOfUsesFloorAndTheOrigin) {
  const SynthesisGrid g(Vector2d(-1, 2), 0.5, 4, 4);
  EXPECT_EQ(g.cell_of(-1, 2), (Cell{0, 0}));
  EXPECT_EQ(g.cell_of(-0.26, 2.74), (Cell{1, 1}));
  EXPECT_EQ(g.cell_of(-1.01, 1.99), (Cell{-1, -1}));  // outside, not truncated towards 0
  EXPECT_FALSE(g.contains(g.cell_of(-1.01, 2.1)));
  EXPECT_EQ(g.cell(g.index({3, 2})), (Cell{3, 2}));
}

TEST(SynthesisGrid, AssignFacesListsEveryTouchedCell) {
  const SynthesisGrid g(Vector2d(0, 0), 1.0, 4, 3);
  MatrixX3d V(9, 3);
  V << 0.2, 0.2, 0, 0.8, 0.2, 0, 0.5, 0.7, 0,  // inside cell (0, 0)
      0.5, 0.5, 0, 2.5, 0.5, 0, 1.5, 1.5, 0,   // spans cells x 0..2, y 0..1
      -3, -3, 0, -2, -3, 0, -2, -2, 0;         // outside the grid
  MatrixX3i F(3, 3);
  F << 0, 1, 2, 3, 4, 5, 6, 7, 8;
  const auto cells = g.assign_faces(V, F);
  ASSERT_EQ(static_cast<int>(cells.size()), g.num_cells());
  for (int i = 0; i < g.num_cells(); ++i) {
    const Cell c = g.cell(i);
    const bool has0 = std::find(cells[i].begin(), cells[i].end(), 0) != cells[i].end();
    const bool has1 = std::find(cells[i].begin(), cells[i].end(), 1) != cells[i].end();
    const bool has2 = std::find(cells[i].begin(), cells[i].end(), 2) != cells[i].end();
    EXPECT_EQ(has0, c.x == 0 && c.y == 0) << c.x << "," << c.y;
    EXPECT_EQ(has1, c.x <= 2 && c.y <= 1) << c.x << "," << c.y;
    EXPECT_FALSE(has2);
  }
}

TEST(SynthesisGrid, RejectsImpossibleSizes) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(SynthesisGrid(Vector2d(0, 0), 0.0, 3, 3), InvalidInput);
  EXPECT_THROW(SynthesisGrid(Vector2d(0, 0), -1.0, 3, 3), InvalidInput);
  EXPECT_THROW(SynthesisGrid(Vector2d(0, 0), nan, 3, 3), InvalidInput);
  EXPECT_THROW(SynthesisGrid(Vector2d(nan, 0), 1.0, 3, 3), InvalidInput);
  EXPECT_THROW(SynthesisGrid(Vector2d(0, 0), 1.0, 0, 3), InvalidInput);
  EXPECT_THROW(SynthesisGrid(Vector2d(0, 0), 1.0, 3, -1), InvalidInput);
  EXPECT_THROW(SynthesisGrid(Vector2d(0, 0), 1.0, 1 << 14, 1 << 14), InvalidInput);
}

TEST(OverlapRegion, ProcessedCellsInsideThePatchOnly) {
  SynthesisGrid g(Vector2d(0, 0), 1.0, 6, 6);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 3; ++x) g.set_processed({x, y});
  const OverlapRegion r(Vector2d(1.5, 1.5), Vector2d(4.5, 4.5), g.processed_snapshot());
  EXPECT_TRUE(r.contains(2.5, 2.5));   // processed, in the patch
  EXPECT_FALSE(r.contains(0.5, 2.5));  // processed, outside the patch
  EXPECT_FALSE(r.contains(3.5, 2.5));  // in the patch, not processed
  EXPECT_TRUE(r.in_patch(3.5, 2.5));
  EXPECT_FALSE(r.contains(-0.5, 2.0));  // outside the grid
  // A snapshot: cells processed afterwards do not join the region.
  g.set_processed({3, 2});
  EXPECT_FALSE(r.contains(3.5, 2.5));
}

}  // namespace
}  // namespace mq
