#include <gtest/gtest.h>

#include "core/mesh/mesh_topology.h"
#include "core/surface/points_near_2d.h"
#include "core/surface/synthesis_front.h"

namespace mq {
namespace {

// A strip of 6 faces, each adjacent to the one before and after it.
MatrixX3i strip_adjacency() {
  MatrixX3i TT(6, 3);
  for (int f = 0; f < 6; ++f) TT.row(f) << (f > 0 ? f - 1 : -1), (f < 5 ? f + 1 : -1), -1;
  return TT;
}

TEST(SynthesisFront, NextIsTheFaceWithTheMostSynthesisedNeighboursLowestFirst) {
  const MatrixX3i TT = strip_adjacency();
  SynthesisFront front(TT);
  EXPECT_EQ(front.next(), 0);  // nothing synthesised: the lowest index
  front.mark(3);
  EXPECT_EQ(front.next(), 2);  // 2 and 4 have one synthesised neighbour each
  front.mark(5);
  EXPECT_EQ(front.next(), 4);  // between two synthesised faces
  front.mark(5);               // again: no effect
  EXPECT_EQ(front.num_synthesised(), 2);
  EXPECT_TRUE(front.synthesised(3) && front.synthesised(5) && !front.synthesised(4));
  for (const int f : {4, 2, 1, 0}) front.mark(f);
  EXPECT_TRUE(front.empty());
  EXPECT_EQ(front.num_synthesised(), 6);
}

TEST(PointsNear2D, FindsExactlyThePointsWithinTheRadius) {
  PointsNear2D points(0.5);
  points.add(Vector2d(1, 1));
  points.add(Vector2d(-3, 2));
  EXPECT_TRUE(points.any_within(Vector2d(1.3, 1.4)));   // 0.5 away: within
  EXPECT_FALSE(points.any_within(Vector2d(1.5, 1.1)));  // 0.51 away
  EXPECT_TRUE(points.any_within(Vector2d(-3.49, 2)));   // across a cell border
  EXPECT_FALSE(points.any_within(Vector2d(0, 0)));
}

}  // namespace
}  // namespace mq
