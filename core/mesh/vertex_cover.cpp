#include "core/mesh/vertex_cover.h"

#include <algorithm>
#include <iterator>
#include <set>

#include "core/common/errors.h"

namespace mq {

void greedy_vertex_cover(const std::vector<std::pair<int, int>>& edges_in,
                         std::vector<char>& removed) {
  const int n = static_cast<int>(removed.size());
  std::vector<std::pair<int, int>> edges;
  edges.reserve(edges_in.size());
  for (const auto& [a, b] : edges_in) {
    MQ_CHECK(a >= 0 && a < n && b >= 0 && b < n, InvalidInput, "vertex cover: edge (", a, ", ", b,
             ") outside ", n, " vertices");
    if (a != b && !removed[a] && !removed[b]) edges.emplace_back(std::min(a, b), std::max(a, b));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<std::vector<int>> adjacent(static_cast<size_t>(n));
  for (const auto& [a, b] : edges) {
    adjacent[a].push_back(b);
    adjacent[b].push_back(a);
  }
  std::vector<int> degree(static_cast<size_t>(n), 0);
  std::set<std::pair<int, int>> queue;  // (edges to kept vertices, vertex), the largest last
  for (int v = 0; v < n; ++v) {
    degree[v] = static_cast<int>(adjacent[v].size());
    if (degree[v] > 0) queue.emplace(degree[v], v);
  }
  while (!queue.empty()) {
    const auto last = std::prev(queue.end());
    const int v = last->second;
    queue.erase(last);
    removed[v] = 1;
    for (const int u : adjacent[v]) {
      if (removed[u]) continue;
      queue.erase({degree[u], u});
      if (--degree[u] > 0) queue.emplace(degree[u], u);
    }
  }
}

}  // namespace mq
