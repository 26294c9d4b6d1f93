#include <gtest/gtest.h>

#include <random>

#include "core/shell/element_grid.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// 400 elements of 5 random vertices in boxes of random size (a few much larger than the median),
// some skipped: near() finds exactly the inserted elements whose boxes meet the query, as a pass
// over all of them does.
TEST(ElementGrid, NearFindsWhatABruteForcePassFinds) {
  std::mt19937_64 rng(3);
  const int ne = 400, per = 5;
  MatrixX3d V(ne * per, 3);
  std::vector<Eigen::Index> first(ne + 1, 0);
  std::vector<char> skip(ne, 0);
  for (int k = 0; k < ne; ++k) {
    const Vector3d c(test::uniform(rng, 0, 10), test::uniform(rng, 0, 10),
                     test::uniform(rng, 0, 2));
    const double size = k % 50 == 0 ? 3.0 : test::uniform(rng, 0.1, 0.5);
    for (int i = 0; i < per; ++i)
      V.row(k * per + i) =
          (c + size * Vector3d(test::uniform(rng, -1, 1), test::uniform(rng, -1, 1),
                               test::uniform(rng, -1, 1)))
              .transpose();
    first[k + 1] = (k + 1) * per;
    skip[k] = k % 7 == 3;
  }
  ElementGrid grid(V, first, skip);
  int found_some = 0;
  for (int q = 0; q < 200; ++q) {
    BoundingBox b;
    const Vector3d c(test::uniform(rng, -1, 11), test::uniform(rng, -1, 11),
                     test::uniform(rng, 0, 2));
    b.extend(c);
    b.extend(c + Vector3d::Constant(test::uniform(rng, 0.05, 1.5)));
    std::vector<int> expected;
    for (int k = 0; k < ne; ++k)
      if (!skip[k] && ElementGrid::overlap(b, grid.box[k])) expected.push_back(k);
    EXPECT_EQ(grid.near(b), expected);
    found_some += !expected.empty();
  }
  EXPECT_GT(found_some, 50);  // the queries do meet elements
  // An inserted element is found from then on.
  grid.insert(3, grid.box[3]);
  const std::vector<int> after = grid.near(grid.box[3]);
  EXPECT_TRUE(std::find(after.begin(), after.end(), 3) != after.end());
}

}  // namespace
}  // namespace mq
