// A small vertex cover of a graph: which elements to remove so that no two kept ones touch.
#pragma once

#include <utility>
#include <vector>

namespace mq {

// Marks vertices in `removed` (one flag per vertex, some possibly set already) until every edge
// has a removed end, greedily: the vertex with the most edges to kept vertices goes first, ties to
// the higher index. A star loses only its centre, a path a-b-c only b. Edges are vertex pairs in
// either order, repeats and self-loops ignored; the result depends only on the set of edges.
// Throws InvalidInput for a vertex outside [0, removed.size()). O(E log E).
void greedy_vertex_cover(const std::vector<std::pair<int, int>>& edges, std::vector<char>& removed);

}  // namespace mq
