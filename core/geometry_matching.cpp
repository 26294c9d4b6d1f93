#include "core/geometry_matching.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace mq {

void gather_subpatch(const std::vector<const Element*>& elements, const Vector2d& lo,
                     const Vector2d& hi, int max_points, MatrixX3d& P, MatrixX3d& NP) {
  std::vector<std::pair<const Element*, int>> inside;
  for (const Element* e : elements)
    for (int v = 0; v < e->V.rows(); ++v) {
      const double x = e->V(v, 0), y = e->V(v, 1);
      // Vertices without a finite normal (all their faces degenerate) cannot enter Eq. (1).
      if (x >= lo.x() && x <= hi.x() && y >= lo.y() && y <= hi.y() && e->N.row(v).allFinite())
        inside.emplace_back(e, v);
    }
  const size_t n =
      max_points > 0 ? std::min(inside.size(), static_cast<size_t>(max_points)) : inside.size();
  P.resize(static_cast<Eigen::Index>(n), 3);
  NP.resize(static_cast<Eigen::Index>(n), 3);
  for (size_t i = 0; i < n; ++i) {
    const auto [e, v] = inside[i * inside.size() / n];
    P.row(static_cast<Eigen::Index>(i)) = e->V.row(v);
    NP.row(static_cast<Eigen::Index>(i)) = e->N.row(v);
  }
}

MatrixX3d whole_cell_offsets(const Vector2d& t_min, const Vector2d& t_max, double cell) {
  const int kx0 = static_cast<int>(std::ceil(t_min.x() / cell - 1e-9));
  const int ky0 = static_cast<int>(std::ceil(t_min.y() / cell - 1e-9));
  const int kx1 = static_cast<int>(std::floor(t_max.x() / cell + 1e-9));
  const int ky1 = static_cast<int>(std::floor(t_max.y() / cell + 1e-9));
  std::vector<Vector3d> offsets;
  for (int ky = ky0; ky <= ky1; ++ky)
    for (int kx = kx0; kx <= kx1; ++kx) offsets.emplace_back(kx * cell, ky * cell, 0.0);
  if (offsets.empty()) offsets.emplace_back(t_max.x(), t_max.y(), 0.0);
  MatrixX3d T(static_cast<Eigen::Index>(offsets.size()), 3);
  for (size_t i = 0; i < offsets.size(); ++i)
    T.row(static_cast<Eigen::Index>(i)) = offsets[i].transpose();
  return T;
}

namespace {

// n evenly strided rows of P and NP (n < #P).
void strided_subset(const MatrixX3d& P, const MatrixX3d& NP, Eigen::Index n, MatrixX3d& Ps,
                    MatrixX3d& Ns) {
  Ps.resize(n, 3);
  Ns.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index k = i * P.rows() / n;
    Ps.row(i) = P.row(k);
    Ns.row(i) = NP.row(k);
  }
}

}  // namespace

OffsetChoice choose_offset(const SwatchFaceTree& swatch, TranslationCostEvaluator& evaluator,
                           const MatrixX3d& P, const MatrixX3d& NP, const MatrixX3d& candidates,
                           const Vector2d& t_min, const Vector2d& t_max, double cell_size,
                           const MatchingOptions& options, std::mt19937_64& rng) {
  MQ_CHECK(candidates.rows() > 0, InvalidInput, "geometry matching needs at least one offset");
  OffsetChoice choice;
  choice.candidates = static_cast<int>(candidates.rows());
  if (P.rows() == 0) {
    // Nothing to match against: the first admissible placement.
    choice.offset = candidates.row(0).transpose();
    return choice;
  }
  TranslationCostProblem problem;
  problem.lambda = options.lambda;
  // The candidates scored on all points: every one, or the best few of a screening pass.
  MatrixX3d finalists = candidates;
  if (options.screen_keep > 0 && options.screen_points > 0 &&
      candidates.rows() > options.screen_keep && P.rows() > options.screen_points) {
    strided_subset(P, NP, options.screen_points, problem.points, problem.point_normals);
    problem.offsets = candidates;
    const Eigen::VectorXd screen = evaluator.evaluate(swatch, problem);
    choice.evaluations += static_cast<int>(screen.size());
    choice.point_offsets += static_cast<long long>(screen.size()) * problem.points.rows();
    std::vector<int> order(static_cast<size_t>(screen.size()));
    for (int i = 0; i < screen.size(); ++i) order[static_cast<size_t>(i)] = i;
    // Ties go to the lower index, so the finalists do not depend on the sort's internals.
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return screen(a) < screen(b); });
    order.resize(static_cast<size_t>(options.screen_keep));
    std::sort(order.begin(), order.end());  // candidate order, so ties resolve as without it
    finalists.resize(options.screen_keep, 3);
    for (int i = 0; i < options.screen_keep; ++i)
      finalists.row(i) = candidates.row(order[static_cast<size_t>(i)]);
  }
  problem.points = P;
  problem.point_normals = NP;
  problem.offsets = finalists;
  const Eigen::VectorXd costs = evaluator.evaluate(swatch, problem);
  choice.evaluations += static_cast<int>(costs.size());
  choice.point_offsets += static_cast<long long>(costs.size()) * P.rows();
  int best = best_offset(costs);
  if (options.epsilon > 0) {
    std::vector<int> near;
    for (int i = 0; i < costs.size(); ++i)
      if (costs(i) <= costs(best) * (1 + options.epsilon)) near.push_back(i);
    best = near[rng() % near.size()];
  }
  Vector3d t = finalists.row(best).transpose();
  double cost = costs(best);
  if (options.refine_to > 0) {
    // Compass search: try the four axis moves of the current step; move to the best improving
    // one, else halve the step. Moves stay within the admissible range.
    const Vector2d lo = t_min, hi = t_max.cwiseMax(t_min);
    double step = 0.5 * cell_size;
    problem.offsets.resize(4, 3);
    // The refinement only polishes a placement already chosen exactly among whole cells, so it
    // matches a fixed, evenly strided subset of the sub-patch (its cost is then comparable
    // between the moves, which is all the search needs).
    if (P.rows() > options.refine_points) {
      strided_subset(P, NP, options.refine_points, problem.points, problem.point_normals);
      problem.offsets = t.transpose();
      cost = evaluator.evaluate(swatch, problem)(0);  // the start point on the subset
      ++choice.evaluations;
      problem.offsets.resize(4, 3);
    }
    while (step >= options.refine_to * cell_size) {
      const Vector3d moves[4] = {{step, 0, 0}, {-step, 0, 0}, {0, step, 0}, {0, -step, 0}};
      for (int k = 0; k < 4; ++k) {
        Vector3d c = t + moves[k];
        c.x() = std::clamp(c.x(), lo.x(), hi.x());
        c.y() = std::clamp(c.y(), lo.y(), hi.y());
        problem.offsets.row(k) = c.transpose();
      }
      const Eigen::VectorXd c = evaluator.evaluate(swatch, problem);
      choice.evaluations += 4;
      choice.point_offsets += 4 * problem.points.rows();
      const int k = best_offset(c);
      // Require a real improvement so float noise cannot make the search wander.
      if (c(k) < cost * (1 - 1e-9)) {
        t = problem.offsets.row(k).transpose();
        cost = c(k);
      } else {
        step *= 0.5;
      }
    }
  }
  choice.offset = t;
  choice.cost = cost;  // on the refinement subset when it was used
  return choice;
}

}  // namespace mq
