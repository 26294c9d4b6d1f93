// Disjoint sets over 0..n-1 with path halving; a set is named by its smallest member, so the
// result does not depend on the order of the unions.
#pragma once

#include <algorithm>
#include <numeric>
#include <vector>

namespace mq {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(static_cast<size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace mq
