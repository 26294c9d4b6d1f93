#include "core/planar/geometry_matching.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/errors.h"

namespace mq {

void gather_subpatch(const std::vector<const Element*>& elements, const Vector2d& lo,
                     const Vector2d& hi, int max_points, MatrixX3d& P, MatrixX3d& NP) {
  // Face centroids with face normals, not vertices with vertex normals: Eq. (1) compares n(v)
  // with the swatch's face normals, and at the exact continuation of the output (the swatch
  // placed where it repeats) a centroid lies on a swatch face of the same normal, cost 1,
  // while a vertex normal averages faces 45 degrees apart on a coarse tube (4 sides): 1.77
  // there, more than at some wrong offsets. Measured on 30 x 30 planes of 4-in-1 sheets,
  // interior rings with the swatch's 4 links (partners chosen as in patch_quilting):
  // --detail 16 3x3 / 6x6 100% / 100% (vertices: 26% / 31%), full detail 3x3 100% (79%).
  auto centroid = [](const Element& e, int f) -> Vector3d {
    return (e.V.row(e.F(f, 0)) + e.V.row(e.F(f, 1)) + e.V.row(e.F(f, 2))).transpose() / 3.0;
  };
  auto normal = [](const Element& e, int f) -> Vector3d {
    return (e.V.row(e.F(f, 1)) - e.V.row(e.F(f, 0)))
        .cross(e.V.row(e.F(f, 2)) - e.V.row(e.F(f, 0)))
        .transpose();
  };
  std::vector<std::pair<const Element*, int>> inside;
  for (const Element* e : elements)
    for (int f = 0; f < e->F.rows(); ++f) {
      const Vector3d c = centroid(*e, f);
      // A degenerate face has no normal and cannot enter Eq. (1).
      if (c.x() >= lo.x() && c.x() <= hi.x() && c.y() >= lo.y() && c.y() <= hi.y() &&
          normal(*e, f).norm() > 0)
        inside.emplace_back(e, f);
    }
  const size_t n =
      max_points > 0 ? std::min(inside.size(), static_cast<size_t>(max_points)) : inside.size();
  P.resize(static_cast<Eigen::Index>(n), 3);
  NP.resize(static_cast<Eigen::Index>(n), 3);
  for (size_t i = 0; i < n; ++i) {
    const auto [e, f] = inside[i * inside.size() / n];
    P.row(static_cast<Eigen::Index>(i)) = centroid(*e, f).transpose();
    NP.row(static_cast<Eigen::Index>(i)) = normal(*e, f).normalized().transpose();
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

// Each point's swatch entry attaining its minimum (-1 when none), with that entry's normal
// factor, which stays fixed while the point moves with t.
struct Assignment {
  std::vector<int> entry;
  std::vector<double> normal_factor;
};

// E(t) of Eq. (3) on the points P (normals NP), recording the assignment. Points in parallel;
// the sum in point order (deterministic). hints (optional): an earlier assignment of the same
// points at a nearby t, whose entries start each search (see SwatchFaceTree::min_face_cost).
double assigned_cost(const SwatchFaceTree& swatch, const MatrixX3d& P, const MatrixX3d& NP,
                     const Vector3d& t, double lambda, Assignment& assignment,
                     const Assignment* hints = nullptr) {
  const Eigen::Index n = P.rows();
  assignment.entry.assign(static_cast<size_t>(n), -1);
  assignment.normal_factor.assign(static_cast<size_t>(n), 0.0);
  std::vector<double> minima(static_cast<size_t>(n));
  tbb::parallel_for(
      tbb::blocked_range<Eigen::Index>(0, n, 16), [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
          const size_t k = static_cast<size_t>(i);
          minima[k] =
              swatch.min_face_cost(P.row(i).transpose() - t, NP.row(i).transpose(), lambda,
                                   &assignment.entry[k], kInf, hints ? hints->entry[k] : -1);
          if (assignment.entry[k] >= 0)
            assignment.normal_factor[k] =
                swatch.entry_normal_factor(assignment.entry[k], NP.row(i).transpose());
        }
      });
  double sum = 0;
  for (const double m : minima) sum += m;
  return sum;
}

// The same sum with every point kept on its assigned entry: never below E(t + d), and equal
// to it at d = 0 (bitwise: entry_cost_with_factor repeats min_face_cost's arithmetic), so
// lowering it lowers E (a majorize-minimize step).
double surrogate_cost(const SwatchFaceTree& swatch, const MatrixX3d& P,
                      const Assignment& assignment, const Vector3d& t, double lambda) {
  double sum = 0;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const size_t k = static_cast<size_t>(i);
    if (assignment.entry[k] < 0) return std::numeric_limits<double>::infinity();
    sum += swatch.entry_cost_with_factor(assignment.entry[k], P.row(i).transpose() - t,
                                         assignment.normal_factor[k], lambda);
  }
  return sum;
}

struct RefinedOffset {
  Vector3d offset;
  double cost = 0;      // exact E on the points at offset
  int evaluations = 0;  // exact evaluations (each over all the points)
};

// Sub-cell refinement of t within [lo, hi] (xy) by majorize-minimize: each round assigns every
// point its best swatch face exactly (one tree query per point), then runs a compass search
// (four axis moves, halving the step from half a cell down to refine_to cells) on the cost
// with the assignments frozen, which needs point-triangle distances only. The frozen cost
// bounds the true one from above, so every accepted round lowers the exact E; rounds stop
// when the compass finds no better frozen placement or a round lowers the exact cost by less
// than the relative refine_tolerance (it is then kept). About one exact evaluation per round
// instead of four per compass step. It queries the tree on the host whatever the evaluator: a
// round scores ~128 points, too few to pay for a kernel launch.
RefinedOffset refine_offset(const SwatchFaceTree& swatch, const MatrixX3d& P, const MatrixX3d& NP,
                            Vector3d t, const Vector2d& lo, const Vector2d& hi, double cell_size,
                            const MatchingOptions& options) {
  constexpr int kMaxRounds = 32;  // a bound only: rounds strictly lower E
  RefinedOffset result;
  Assignment assignment, next_assignment;
  double cost = assigned_cost(swatch, P, NP, t, options.lambda, assignment);
  result.evaluations = 1;
  // Later rounds start with a step of twice the previous round's largest move: the faces
  // reassigned after a short move only shift the optimum by about that much.
  double first_step = 0.5 * cell_size;
  for (int round = 0; round < kMaxRounds; ++round) {
    Vector3d u = t;
    double frozen = cost;
    for (double step = first_step; step >= options.refine_to * cell_size;) {
      const Vector3d moves[4] = {{step, 0, 0}, {-step, 0, 0}, {0, step, 0}, {0, -step, 0}};
      // The four moves' frozen costs in parallel (each sums its points in order), then the
      // best in move order: the same choice as evaluating them one after another.
      Vector3d c[4];
      double e[4];
      for (int k = 0; k < 4; ++k) {
        c[k] = u + moves[k];
        c[k].x() = std::clamp(c[k].x(), lo.x(), hi.x());
        c[k].y() = std::clamp(c[k].y(), lo.y(), hi.y());
      }
      tbb::parallel_for(
          0, 4, [&](int k) { e[k] = surrogate_cost(swatch, P, assignment, c[k], options.lambda); });
      double best_cost = frozen;
      Vector3d best_c = u;
      for (int k = 0; k < 4; ++k)
        if (e[k] < best_cost) {
          best_cost = e[k];
          best_c = c[k];
        }
      // Require a real improvement so float noise cannot make the search wander.
      if (best_cost < frozen * (1 - 1e-9)) {
        u = best_c;
        frozen = best_cost;
      } else {
        step *= 0.5;
      }
    }
    if (u == t) break;
    const double moved_by = (u - t).cwiseAbs().maxCoeff();
    first_step = std::min(0.5 * cell_size, std::max(2.0 * moved_by, options.refine_to * cell_size));
    const double moved =
        assigned_cost(swatch, P, NP, u, options.lambda, next_assignment, &assignment);
    ++result.evaluations;
    if (!(moved < cost * (1 - 1e-9))) break;
    const bool converged = moved > cost * (1 - options.refine_tolerance);
    t = u;
    cost = moved;
    std::swap(assignment, next_assignment);
    if (converged) break;
  }
  result.offset = t;
  result.cost = cost;
  return result;
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
    // Ties go to the lower index, and the finalists stay in candidate order, so ties among
    // them resolve as without screening.
    const TranslationCostEvaluator::LeastCostOffsets screened =
        evaluator.least_cost_offsets(swatch, problem, options.screen_keep);
    choice.evaluations += static_cast<int>(candidates.rows());
    choice.point_offsets += screened.point_offsets;
    finalists.resize(static_cast<Eigen::Index>(screened.kept.size()), 3);
    for (size_t i = 0; i < screened.kept.size(); ++i)
      finalists.row(static_cast<Eigen::Index>(i)) = candidates.row(screened.kept[i]);
  }
  // The finalists are scored on the points the refinement polishes with: the offset it returns
  // minimises that subset's cost, so the start is chosen by the same measure. Without
  // refinement, on every point.
  const bool refine = options.refine_to > 0;
  if (refine && P.rows() > options.refine_points) {
    strided_subset(P, NP, options.refine_points, problem.points, problem.point_normals);
  } else {
    problem.points = P;
    problem.point_normals = NP;
  }
  problem.offsets = finalists;
  const Eigen::VectorXd costs = evaluator.evaluate(swatch, problem);
  choice.evaluations += static_cast<int>(costs.size());
  choice.point_offsets += static_cast<long long>(costs.size()) * problem.points.rows();
  int best = best_offset(costs);
  if (options.epsilon > 0) {
    std::vector<int> near;
    for (int i = 0; i < costs.size(); ++i)
      if (costs(i) <= costs(best) * (1 + options.epsilon)) near.push_back(i);
    best = near[rng() % near.size()];
  }
  Vector3d t = finalists.row(best).transpose();
  double cost = costs(best);
  if (refine) {
    // The refinement only polishes a placement already chosen among whole cells, so it matches
    // the fixed, evenly strided subset of the sub-patch the finalists were scored on.
    const RefinedOffset refined = refine_offset(swatch, problem.points, problem.point_normals, t,
                                                t_min, t_max.cwiseMax(t_min), cell_size, options);
    t = refined.offset;
    cost = refined.cost;  // on the refinement subset
    choice.evaluations += refined.evaluations;
    choice.point_offsets += static_cast<long long>(refined.evaluations) * problem.points.rows();
  }
  choice.offset = t;
  choice.cost = cost;  // on the refinement subset when it was used
  return choice;
}

}  // namespace mq
