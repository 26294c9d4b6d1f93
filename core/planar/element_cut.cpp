#include "core/planar/element_cut.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <tuple>
#include <utility>
#include <vector>

// GCC 12 reports a false -Wmaybe-uninitialized inside Boost's edge iterator (boost::optional);
// clang (the sanitizer build) has no such warning and would warn about the unknown name.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/range/iterator_range.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

namespace {

// One undirected dual edge between faces f and g with its Eq. (7) weight.
struct DualEdge {
  int f, g;
  double weight;
};

void check_inputs(const MatrixX3d& V, const MatrixX3i& F, const Eigen::VectorXd& dist,
                  size_t num_labels, const char* label_name) {
  MQ_CHECK(dist.size() == V.rows(), InvalidInput, "dist_to_other has ", dist.size(),
           " entries but the element has ", V.rows(), " vertices");
  MQ_CHECK(num_labels == static_cast<size_t>(F.rows()), InvalidInput, label_name, " has ",
           num_labels, " entries but the element has ", F.rows(), " faces");
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    MQ_CHECK(V.row(v).allFinite(), InvalidInput, "vertex ", v, " has a non-finite coordinate");
    MQ_CHECK(std::isfinite(dist(v)) && dist(v) >= 0, InvalidInput, "dist_to_other(", v,
             ") = ", dist(v), " is not a finite non-negative distance");
  }
}

// Dual edges in edge order; faces sharing a non-manifold edge are linked pairwise.
std::vector<DualEdge> dual_edges(const MatrixX3d& V, const MatrixX3i& F,
                                 const Eigen::VectorXd& dist) {
  const EdgeTopology topo = edge_topology(F, static_cast<int>(V.rows()));
  std::vector<DualEdge> edges;
  for (int e = 0; e < topo.num_edges(); ++e) {
    const int deg = topo.edge_faces.degree(e);
    if (deg < 2) continue;
    const int i = topo.E(e, 0), j = topo.E(e, 1);
    // Eq. (7): short edges near the other element are cheap to cut.
    const double w = (1.0 + (V.row(i) - V.row(j)).norm()) * (1.0 + dist(i) + dist(j));
    const int* fs = topo.edge_faces.begin(e);
    for (int a = 0; a < deg; ++a)
      for (int b = a + 1; b < deg; ++b) edges.push_back({fs[a], fs[b], w});
  }
  return edges;
}

// The flow network in compressed sparse row form: arcs and their properties in flat arrays
// (an adjacency_list allocated every arc's properties separately, which cost as much as the
// max-flow itself on elements of a few hundred faces).
using ArcDescriptor = boost::detail::csr_edge_descriptor<std::size_t, std::size_t>;
struct ArcProperties {
  double capacity = 0;
  double residual = 0;
  ArcDescriptor reverse;
  std::size_t input = 0;  // position in the arc list given to the constructor
};
using FlowGraph =
    boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, ArcProperties>;
using Arc = boost::graph_traits<FlowGraph>::edge_descriptor;

// Arc list under construction: arcs 2k and 2k + 1 are each other's reverse.
struct ArcList {
  std::vector<std::pair<std::size_t, std::size_t>> ends;
  std::vector<ArcProperties> properties;
  // Adds u->v with capacity cap_uv and v->u with capacity cap_vu.
  void add_pair(int u, int v, double cap_uv, double cap_vu) {
    for (const auto& [a, b, cap] : {std::tuple{u, v, cap_uv}, std::tuple{v, u, cap_vu}}) {
      ArcProperties p;
      p.capacity = cap;
      p.input = ends.size();
      ends.emplace_back(a, b);
      properties.push_back(p);
    }
  }
};

// The graph, with every arc's reverse set.
FlowGraph build_flow_graph(const ArcList& arcs, std::size_t num_vertices) {
  FlowGraph g(boost::edges_are_unsorted_multi_pass, arcs.ends.begin(), arcs.ends.end(),
              arcs.properties.begin(), num_vertices);
  std::vector<Arc> by_input(arcs.ends.size());
  for (const Arc& a : boost::make_iterator_range(boost::edges(g))) by_input[g[a].input] = a;
  for (const Arc& a : boost::make_iterator_range(boost::edges(g)))
    g[a].reverse = by_input[g[a].input ^ 1];
  return g;
}

}  // namespace

ElementCut element_graph_cut(const MatrixX3d& V, const MatrixX3i& F,
                             const Eigen::VectorXd& dist_to_other,
                             const std::vector<CutLabel>& hard) {
  check_inputs(V, F, dist_to_other, hard.size(), "hard");
  const int nf = static_cast<int>(F.rows());
  ElementCut result;
  result.keep.assign(nf, true);
  if (nf == 0) return result;
  const std::vector<DualEdge> edges = dual_edges(V, F, dist_to_other);

  // Two Keep faces are both on the SOURCE side of every cut, so the edge between them is never
  // cut and the network leaves it out, with the SOURCE link of a Keep face that borders no other
  // kind (such a face is kept, as it is reachable from SOURCE): an output thread stitched at one
  // end is mostly Keep, and the network is then the size of the overlap, not of the thread.
  const int source = nf, sink = nf + 1;
  ArcList arcs;
  arcs.ends.reserve(2 * edges.size() + 2 * static_cast<std::size_t>(nf));
  arcs.properties.reserve(arcs.ends.capacity());
  std::vector<char> in_network(nf, 0);
  double total = 1.0;
  for (const DualEdge& e : edges) {
    if (hard[e.f] == CutLabel::Keep && hard[e.g] == CutLabel::Keep) continue;
    arcs.add_pair(e.f, e.g, e.weight, e.weight);
    total += e.weight;
    in_network[e.f] = in_network[e.g] = 1;
  }
  // "Infinite" terminal links: larger than any finite cut, so never cut, yet finite so that
  // the solver's arithmetic stays exact (inf - inf would give NaN).
  const double infinite = 2.0 * total;
  for (int f = 0; f < nf; ++f) {
    if (hard[f] == CutLabel::Keep && in_network[f]) arcs.add_pair(source, f, infinite, 0.0);
    if (hard[f] == CutLabel::Remove) arcs.add_pair(f, sink, infinite, 0.0);
  }
  FlowGraph g = build_flow_graph(arcs, static_cast<std::size_t>(nf) + 2);
  result.flow = boost::boykov_kolmogorov_max_flow(
      g, boost::get(&ArcProperties::capacity, g), boost::get(&ArcProperties::residual, g),
      boost::get(&ArcProperties::reverse, g), boost::get(boost::vertex_index, g), source, sink);

  // SOURCE side = faces reachable from SOURCE through unsaturated arcs. The tolerance absorbs
  // round-off in residuals of saturated arcs (capacities are >= 1 by Eq. (7)).
  const double tol = 1e-12 * total;
  std::vector<char> reached(nf + 2, 0);
  for (int f = 0; f < nf; ++f) reached[f] = hard[f] == CutLabel::Keep && !in_network[f];
  std::queue<int> queue;
  reached[source] = 1;
  queue.push(source);
  while (!queue.empty()) {
    const int u = queue.front();
    queue.pop();
    for (const Arc& a :
         boost::make_iterator_range(boost::out_edges(static_cast<std::size_t>(u), g))) {
      const int v = static_cast<int>(boost::target(a, g));
      if (!reached[v] && g[a].residual > tol) {
        reached[v] = 1;
        queue.push(v);
      }
    }
  }
  MQ_ASSERT(!reached[sink]);

  // Dual-graph components without any hard label are kept whole (they are not reached).
  std::vector<int> comp(nf, -1);
  std::vector<char> comp_labelled;
  std::vector<std::vector<int>> nbr(nf);
  for (const DualEdge& e : edges) {
    nbr[e.f].push_back(e.g);
    nbr[e.g].push_back(e.f);
  }
  for (int f0 = 0; f0 < nf; ++f0) {
    if (comp[f0] >= 0) continue;
    const int c = static_cast<int>(comp_labelled.size());
    comp_labelled.push_back(0);
    comp[f0] = c;
    queue.push(f0);
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop();
      if (hard[f] != CutLabel::Free) comp_labelled[c] = 1;
      for (int h : nbr[f])
        if (comp[h] < 0) {
          comp[h] = c;
          queue.push(h);
        }
    }
  }
  for (int f = 0; f < nf; ++f) result.keep[f] = reached[f] || !comp_labelled[comp[f]];
  return result;
}

std::vector<bool> graph_cut_keep_faces(const MatrixX3d& V, const MatrixX3i& F,
                                       const Eigen::VectorXd& dist_to_other,
                                       const std::vector<CutLabel>& hard) {
  return element_graph_cut(V, F, dist_to_other, hard).keep;
}

double cut_cost(const MatrixX3d& V, const MatrixX3i& F, const Eigen::VectorXd& dist_to_other,
                const std::vector<bool>& keep) {
  check_inputs(V, F, dist_to_other, keep.size(), "keep");
  double cost = 0;
  for (const DualEdge& e : dual_edges(V, F, dist_to_other))
    if (keep[e.f] != keep[e.g]) cost += e.weight;
  return cost;
}

}  // namespace mq
