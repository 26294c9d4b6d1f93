#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/mesh/vertex_cover.h"

namespace mq {
namespace {

bool covers(const std::vector<std::pair<int, int>>& edges, const std::vector<char>& removed) {
  for (const auto& [a, b] : edges)
    if (a != b && !removed[a] && !removed[b]) return false;
  return true;
}

int count(const std::vector<char>& removed) {
  int n = 0;
  for (const char r : removed) n += r != 0;
  return n;
}

// A ring bent into its four neighbours: only it goes (removing the later of each pair would
// remove the four neighbours instead).
TEST(VertexCover, StarLosesOnlyItsCentre) {
  const std::vector<std::pair<int, int>> edges = {{0, 1}, {0, 2}, {3, 0}, {0, 4}, {0, 4}};
  std::vector<char> removed(5, 0);
  greedy_vertex_cover(edges, removed);
  EXPECT_EQ(removed, (std::vector<char>{1, 0, 0, 0, 0}));
}

TEST(VertexCover, PathLosesItsMiddle) {
  std::vector<char> removed(3, 0);
  greedy_vertex_cover({{0, 1}, {1, 2}}, removed);
  EXPECT_EQ(removed, (std::vector<char>{0, 1, 0}));
}

TEST(VertexCover, TriangleAndAlreadyRemoved) {
  std::vector<char> removed(4, 0);
  greedy_vertex_cover({{0, 1}, {1, 2}, {2, 0}, {3, 3}}, removed);
  EXPECT_EQ(count(removed), 2);
  EXPECT_TRUE(covers({{0, 1}, {1, 2}, {2, 0}}, removed));
  EXPECT_FALSE(removed[3]) << "a self-loop is no conflict";
  // An edge to a vertex removed already needs nothing more.
  std::vector<char> pre = {1, 0, 0};
  greedy_vertex_cover({{0, 1}, {0, 2}}, pre);
  EXPECT_EQ(pre, (std::vector<char>{1, 0, 0}));
}

// A grid of conflicts (each vertex touching its 4 neighbours), in two edge orders: always a
// cover, at most 60% of the vertices, the same for either order.
TEST(VertexCover, GridIsCoveredIndependentlyOfEdgeOrder) {
  const int w = 12;
  std::vector<std::pair<int, int>> edges;
  for (int y = 0; y < w; ++y)
    for (int x = 0; x < w; ++x) {
      if (x + 1 < w) edges.emplace_back(y * w + x, y * w + x + 1);
      if (y + 1 < w) edges.emplace_back(y * w + x, (y + 1) * w + x);
    }
  std::vector<char> a(w * w, 0), b(w * w, 0);
  greedy_vertex_cover(edges, a);
  std::vector<std::pair<int, int>> reversed(edges.rbegin(), edges.rend());
  for (auto& [p, q] : reversed) std::swap(p, q);
  greedy_vertex_cover(reversed, b);
  EXPECT_TRUE(covers(edges, a));
  EXPECT_EQ(a, b);
  EXPECT_LE(count(a), w * w * 6 / 10);
}

TEST(VertexCover, RejectsAVertexOutOfRange) {
  std::vector<char> removed(2, 0);
  EXPECT_THROW(greedy_vertex_cover({{0, 2}}, removed), InvalidInput);
  EXPECT_THROW(greedy_vertex_cover({{-1, 0}}, removed), InvalidInput);
}

}  // namespace
}  // namespace mq
