#include "core/surface/cone_placement.h"

#include <algorithm>
#include <cstdlib>
#include <queue>

#include "core/common/errors.h"

namespace mq {

namespace {

int sign_of(int x) { return (x > 0) - (x < 0); }

// Interior vertices within `reach` edges of v (through interior vertices), v first, then in
// breadth-first order with ascending indices per ring: deterministic.
std::vector<int> neighbourhood(const Adjacency& adj, const std::vector<char>& interior, int v,
                               int reach, std::vector<int>& stamp, int mark) {
  std::vector<int> out{v};
  stamp[v] = mark;
  size_t begin = 0;
  for (int ring = 0; ring < reach; ++ring) {
    const size_t end = out.size();
    for (size_t i = begin; i < end; ++i)
      for (const int* w = adj.begin(out[i]); w != adj.end(out[i]); ++w)
        if (interior[*w] && stamp[*w] != mark) {
          stamp[*w] = mark;
          out.push_back(*w);
        }
    begin = end;
  }
  return out;
}

// Moves the cones of `index` towards lower E (see place_cones); u and energy are kept current.
void move_cones(const TrivialConnection& solver, const Adjacency& adj,
                const ConePlacementOptions& options, std::vector<int>& index, Eigen::VectorXd& u,
                double& energy, std::vector<int>& stamp, int& mark, ConePlacementReport& rep) {
  const int nv = static_cast<int>(index.size());
  const std::vector<char>& interior = solver.interior();
  const double unit = kTwoPi / solver.N();
  int reach = options.reach;
  for (int round = 0; round < options.max_rounds && reach >= 1; ++round) {
    // dE/dk_v = 2 (P (A u))_v, P the inverse of the factorised -Delta, k_v the curvature at v:
    // moving a cone of curvature c from v to w changes E by about 2 c (s_w - s_v).
    const Eigen::VectorXd s = solver.solve_poisson(solver.vertex_area().cwiseProduct(
        options.target.size() ? misfit(solver, u, options.target) : u));
    std::vector<int> next = index;
    int moved = 0, cancelled = 0;
    for (int v = 0; v < nv; ++v) {
      if (index[v] == 0 || !interior[v]) continue;
      const int k = index[v];
      const double c = k * unit;
      int best = v;
      double best_value = c * s(v);
      for (const int w : neighbourhood(adj, interior, v, reach, stamp, mark++)) {
        // Never onto a cone of the same sign (that would make a pole again).
        if (w == v || sign_of(next[w]) == sign_of(k)) continue;
        if (c * s(w) < best_value - 1e-12 * std::abs(best_value)) {
          best_value = c * s(w);
          best = w;
        }
      }
      if (best == v) continue;
      if (next[best] != 0 && sign_of(next[best]) != sign_of(k)) ++cancelled;
      next[v] -= k;
      next[best] += k;
      ++moved;
    }
    if (moved == 0) break;
    const Eigen::VectorXd u_next = solver.log_scale(next, options.target);
    const double e_next = scale_energy(solver, u_next, options.target);
    ++rep.rounds;
    if (e_next < energy) {
      index = std::move(next);
      u = u_next;
      energy = e_next;
      rep.moves += moved;
      rep.cancelled += cancelled;
    } else {
      reach /= 2;
    }
  }
}

// The + cone and - cone (unit cones of one component) whose cancelling gives the lowest E, tried
// for each + cone against its options.pair_candidates nearest - cones (breadth-first through
// interior vertices, ties by index): false when there is none or the solve budget is spent.
struct PairChoice {
  int plus = -1, minus = -1;
  double energy = kInf;
  Eigen::VectorXd u;
};

bool best_cone_pair(const TrivialConnection& solver, const Adjacency& adj,
                    const ConePlacementOptions& options, const std::vector<int>& index,
                    std::vector<int>& stamp, int& mark, int& solves, PairChoice& best) {
  const int nv = static_cast<int>(index.size());
  const std::vector<char>& interior = solver.interior();
  best = PairChoice();
  for (int p = 0; p < nv; ++p) {
    if (index[p] <= 0 || !interior[p]) continue;
    // Breadth-first from p until enough - cones are found.
    std::vector<int> found, ring{p};
    stamp[p] = mark;
    while (!ring.empty() && static_cast<int>(found.size()) < options.pair_candidates) {
      std::vector<int> next;
      for (const int v : ring)
        for (const int* w = adj.begin(v); w != adj.end(v); ++w)
          if (interior[*w] && stamp[*w] != mark) {
            stamp[*w] = mark;
            next.push_back(*w);
          }
      std::sort(next.begin(), next.end());
      for (const int w : next)
        if (index[w] < 0 && static_cast<int>(found.size()) < options.pair_candidates)
          found.push_back(w);
      ring = std::move(next);
    }
    ++mark;
    for (const int n : found) {
      if (solves >= options.max_pair_solves) return best.plus >= 0;
      std::vector<int> trial = index;
      trial[p] -= 1;
      trial[n] += 1;
      Eigen::VectorXd u = solver.log_scale(trial, options.target);
      ++solves;
      const double e = scale_energy(solver, u, options.target);
      if (e < best.energy) best = {p, n, e, std::move(u)};
    }
  }
  return best.plus >= 0;
}

// Cancels + and - cone pairs while the best raises E by at most options.pair_allowance (see
// place_cones), moving the others again after each.
void cancel_cone_pairs(const TrivialConnection& solver, const Adjacency& adj,
                       const ConePlacementOptions& options, std::vector<int>& index,
                       Eigen::VectorXd& u, double& energy, std::vector<int>& stamp, int& mark,
                       ConePlacementReport& rep) {
  int solves = 0;
  PairChoice best;
  while (best_cone_pair(solver, adj, options, index, stamp, mark, solves, best) &&
         best.energy <= energy + options.pair_allowance) {
    index[best.plus] -= 1;
    index[best.minus] += 1;
    u = std::move(best.u);
    energy = best.energy;
    ++rep.cancelled;
    ++rep.pairs_cancelled;
    move_cones(solver, adj, options, index, u, energy, stamp, mark, rep);
  }
}

}  // namespace

Eigen::VectorXd misfit(const TrivialConnection& solver, const Eigen::VectorXd& u,
                       const Eigen::VectorXd& target) {
  // Per component, less its area-weighted mean: the overall size is the normalisation's
  // (core/surface/global_quilting), and a cone cannot move u's mean on a closed component.
  Eigen::VectorXd d = u - target;
  const std::vector<int>& component = solver.vertex_component();
  const Eigen::VectorXd& a = solver.vertex_area();
  const int nc = d.size() ? *std::max_element(component.begin(), component.end()) + 1 : 0;
  std::vector<double> sum(static_cast<size_t>(nc), 0), area(static_cast<size_t>(nc), 0);
  for (Eigen::Index v = 0; v < d.size(); ++v) {
    sum[component[v]] += a(v) * d(v);
    area[component[v]] += a(v);
  }
  for (Eigen::Index v = 0; v < d.size(); ++v)
    if (area[component[v]] > 0) d(v) -= sum[component[v]] / area[component[v]];
  return d;
}

double scale_energy(const TrivialConnection& solver, const Eigen::VectorXd& u,
                    const Eigen::VectorXd& target) {
  const Eigen::VectorXd& a = solver.vertex_area();
  const double total = a.sum();
  if (!(total > 0)) return 0.0;
  if (target.size() == 0) return a.dot(u.cwiseProduct(u)) / total;
  const Eigen::VectorXd d = misfit(solver, u, target);
  return a.dot(d.cwiseProduct(d)) / total;
}

std::vector<int> place_cones(const TrivialConnection& solver, std::vector<int> index,
                             const Adjacency& adj, const ConePlacementOptions& options,
                             ConePlacementReport* report) {
  const int nv = static_cast<int>(index.size());
  MQ_CHECK(nv == static_cast<int>(solver.interior().size()) && adj.size() == nv, InvalidInput,
           "cone placement: ", nv, " indices for ", solver.interior().size(), " vertices");
  MQ_CHECK(options.max_rounds >= 0 && options.reach >= 1, InvalidInput,
           "cone placement: max_rounds must be >= 0 and reach >= 1");
  MQ_CHECK(options.pair_candidates >= 1 && options.max_pair_solves >= 0, InvalidInput,
           "cone placement: pair_candidates must be >= 1 and max_pair_solves >= 0");
  MQ_CHECK(options.target.size() == 0 || options.target.size() == nv, InvalidInput,
           "cone placement: ", options.target.size(), " target scales for ", nv, " vertices");
  ConePlacementReport rep;
  const std::vector<char>& interior = solver.interior();
  std::vector<int> stamp(static_cast<size_t>(nv), -1);
  int mark = 0;
  // Unit cones: a pole (a whole turn of a line field) is two half-turn cones at one place.
  for (int v = 0; v < nv; ++v) {
    if (!interior[v]) continue;
    while (std::abs(index[v]) > 1) {
      const int s = sign_of(index[v]);
      int target = -1;
      for (int reach = 1; target < 0 && reach <= 64; ++reach)
        for (const int w : neighbourhood(adj, interior, v, reach, stamp, mark++))
          if (w != v && index[w] == 0) {
            target = w;
            break;
          }
      if (target < 0) break;
      index[v] -= s;
      index[target] += s;
      ++rep.split_poles;
    }
  }
  Eigen::VectorXd u = solver.log_scale(index, options.target);
  double energy = scale_energy(solver, u, options.target);
  rep.energy_before = energy;
  move_cones(solver, adj, options, index, u, energy, stamp, mark, rep);
  if (options.pair_allowance >= 0)
    cancel_cone_pairs(solver, adj, options, index, u, energy, stamp, mark, rep);
  rep.energy_after = energy;
  if (report) *report = rep;
  return index;
}

}  // namespace mq
