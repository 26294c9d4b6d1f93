// Geometry matching (paper section 2.4): the offset chosen by choose_offset on a periodic swatch.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <utility>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/planar/geometry_matching.h"
#include "core/planar/swatch_generators.h"

namespace mq {
namespace {

// A small chain mail sheet: periods 2.5 (x) and 1.25 (y), cells of a quarter / half period.
struct PeriodicFixture {
  ChainMailOptions options;
  TriMesh swatch;
  double cell = 0.625;
  PeriodicFixture() {
    options.rows = 4;
    options.cols = 4;
    options.ring_segments = 24;
    options.wire_segments = 8;
    swatch = chainmail_4in1(options);
  }
  double px() const { return chainmail_period_x(options); }
  double py() const { return chainmail_period_y(options); }

  // Face centroids (with exact face normals) of the swatch inside [x0,x1] x [y0,y1], moved by
  // `shift`: an output sub-patch that the swatch matches exactly at t = shift (+ periods).
  void subpatch(double x0, double x1, double y0, double y1, const Vector3d& shift, MatrixX3d& P,
                MatrixX3d& NP) const {
    const MatrixX3d FN = face_normals(swatch.V, swatch.F);
    std::vector<int> faces;
    for (int f = 0; f < swatch.num_faces(); ++f) {
      const Vector3d c = centroid(f);
      if (c.x() >= x0 && c.x() <= x1 && c.y() >= y0 && c.y() <= y1) faces.push_back(f);
    }
    P.resize(static_cast<Eigen::Index>(faces.size()), 3);
    NP.resize(P.rows(), 3);
    for (size_t i = 0; i < faces.size(); ++i) {
      P.row(static_cast<Eigen::Index>(i)) = (centroid(faces[i]) + shift).transpose();
      NP.row(static_cast<Eigen::Index>(i)) = FN.row(faces[i]);
    }
  }
  Vector3d centroid(int f) const {
    return (swatch.V.row(swatch.F(f, 0)) + swatch.V.row(swatch.F(f, 1)) +
            swatch.V.row(swatch.F(f, 2)))
               .transpose() /
           3.0;
  }
  // Whole-cell offsets kx * cell, ky * cell for kx, ky in [lo, hi].
  MatrixX3d candidates(int lo, int hi) const {
    const int n = hi - lo + 1;
    MatrixX3d T(n * n, 3);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) T.row(j * n + i) << (lo + i) * cell, (lo + j) * cell, 0.0;
    return T;
  }
};

// Distance from a to the nearest b + (i px, j py).
double periodic_distance(const Vector3d& a, const Vector3d& b, double px, double py) {
  const double dx = a.x() - b.x(), dy = a.y() - b.y();
  const double rx = dx - px * std::round(dx / px), ry = dy - py * std::round(dy / py);
  return std::sqrt(rx * rx + ry * ry + (a.z() - b.z()) * (a.z() - b.z()));
}

TEST(GeometryMatching, PeriodicSwatchFindsAnExactPeriodOffset) {
  const PeriodicFixture fx;
  const SwatchFaceTree grid(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  MatrixX3d P, NP;
  const Vector3d shift(fx.px(), fx.py(), 0);  // 4 and 2 cells
  fx.subpatch(2.0, 4.0, 1.5, 3.0, shift, P, NP);
  ASSERT_GT(P.rows(), 50);
  MatchingOptions options;
  options.lambda = 1.0 / fx.cell;
  options.refine_to = 0;    // whole cells only
  options.screen_keep = 0;  // every candidate on every point
  std::mt19937_64 rng(1);
  const MatrixX3d T = fx.candidates(-2, 8);
  const OffsetChoice c = choose_offset(grid, cpu, P, NP, T, Vector2d(-2, -2) * fx.cell,
                                       Vector2d(8, 8) * fx.cell, fx.cell, options, rng);
  EXPECT_EQ(c.candidates, T.rows());
  EXPECT_EQ(c.point_offsets, T.rows() * P.rows());
  EXPECT_LT(periodic_distance(c.offset, shift, fx.px(), fx.py()), 1e-9) << c.offset.transpose();
  // Every point lies on a face with the same normal: each Eq. (2) term is exactly 1.
  EXPECT_NEAR(c.cost, static_cast<double>(P.rows()), 1e-6 * P.rows());
  // And the offsets off the period cost clearly more (the test has a real choice to make).
  TranslationCostProblem pb;
  pb.points = P;
  pb.point_normals = NP;
  pb.lambda = options.lambda;
  pb.offsets = T;
  const Eigen::VectorXd costs = cpu.evaluate(grid, pb);
  int off_period = 0;
  for (Eigen::Index i = 0; i < T.rows(); ++i)
    if (periodic_distance(T.row(i).transpose(), shift, fx.px(), fx.py()) > 1e-9) {
      ++off_period;
      EXPECT_GT(costs(i), 1.05 * c.cost) << "offset " << T.row(i);
    }
  EXPECT_GT(off_period, 100);
}

TEST(GeometryMatching, ScreeningKeepsTheExhaustiveChoiceAtAFractionOfTheWork) {
  const PeriodicFixture fx;
  const SwatchFaceTree grid(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  MatrixX3d P, NP;
  const Vector3d shift(fx.px(), fx.py(), 0);
  fx.subpatch(2.0, 4.0, 1.5, 3.0, shift, P, NP);
  MatchingOptions options;
  options.lambda = 1.0 / fx.cell;
  options.refine_to = 0;
  options.screen_points = 32;
  options.screen_keep = 4;
  ASSERT_GT(P.rows(), options.screen_points);
  const MatrixX3d T = fx.candidates(-2, 8);
  std::mt19937_64 rng(1);
  const OffsetChoice screened = choose_offset(grid, cpu, P, NP, T, Vector2d(-2, -2) * fx.cell,
                                              Vector2d(8, 8) * fx.cell, fx.cell, options, rng);
  options.screen_keep = 0;
  const OffsetChoice exhaustive = choose_offset(grid, cpu, P, NP, T, Vector2d(-2, -2) * fx.cell,
                                                Vector2d(8, 8) * fx.cell, fx.cell, options, rng);
  EXPECT_EQ(screened.offset, exhaustive.offset);
  EXPECT_DOUBLE_EQ(screened.cost, exhaustive.cost);  // the finalists are scored on every point
  // Screening scores each candidate on at most 32 points (fewer once its partial sum rules it
  // out; the four finalists on all 32), then the four finalists on every point.
  EXPECT_LT(screened.point_offsets, T.rows() * 32 + 4 * P.rows());
  EXPECT_GE(screened.point_offsets, 4 * 32 + 4 * P.rows());
  EXPECT_LT(screened.point_offsets, exhaustive.point_offsets / 5);
}

TEST(GeometryMatching, RefinementRecoversASubCellShift) {
  const PeriodicFixture fx;
  const SwatchFaceTree grid(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  MatrixX3d P, NP;
  const Vector3d shift(fx.px() + 0.2, fx.py() - 0.15, 0);  // +0.32 and -0.24 of a cell
  fx.subpatch(2.0, 4.0, 1.5, 3.0, shift, P, NP);
  MatchingOptions options;
  options.lambda = 1.0 / fx.cell;
  options.refine_to = 1e-3;
  std::mt19937_64 rng(1);
  const OffsetChoice c =
      choose_offset(grid, cpu, P, NP, fx.candidates(-2, 8), Vector2d(-2, -2) * fx.cell,
                    Vector2d(8, 8) * fx.cell, fx.cell, options, rng);
  EXPECT_GT(c.evaluations, c.candidates);  // the refinement ran
  EXPECT_LT(periodic_distance(c.offset, shift, fx.px(), fx.py()), 0.01 * fx.cell)
      << c.offset.transpose();
  EXPECT_EQ(c.offset.z(), 0.0);
  // Without refinement the best is the nearest whole cell, off by a third of a cell.
  options.refine_to = 0;
  const OffsetChoice whole =
      choose_offset(grid, cpu, P, NP, fx.candidates(-2, 8), Vector2d(-2, -2) * fx.cell,
                    Vector2d(8, 8) * fx.cell, fx.cell, options, rng);
  EXPECT_GT(periodic_distance(whole.offset, shift, fx.px(), fx.py()), 0.25 * fx.cell);
}

TEST(GeometryMatching, RefinementStaysInTheAdmissibleRange) {
  const PeriodicFixture fx;
  const SwatchFaceTree grid(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  MatrixX3d P, NP;
  fx.subpatch(2.0, 4.0, 1.5, 3.0, Vector3d(fx.px() + 0.2, fx.py() - 0.15, 0), P, NP);
  MatchingOptions options;
  options.lambda = 1.0 / fx.cell;
  std::mt19937_64 rng(1);
  // The true shift lies outside this range: the search must stop at its border.
  const Vector2d lo(0, 0), hi(fx.px(), fx.py());
  const OffsetChoice c =
      choose_offset(grid, cpu, P, NP, fx.candidates(0, 2), lo, hi, fx.cell, options, rng);
  EXPECT_GE(c.offset.x(), lo.x());
  EXPECT_GE(c.offset.y(), lo.y());
  EXPECT_LE(c.offset.x(), hi.x());
  EXPECT_LE(c.offset.y(), hi.y());
}

TEST(GeometryMatching, VarietyIsSeededAndStaysNearTheMinimum) {
  const PeriodicFixture fx;
  const SwatchFaceTree grid(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  MatrixX3d P, NP;
  fx.subpatch(2.0, 4.0, 1.5, 3.0, Vector3d(fx.px(), fx.py(), 0), P, NP);
  const MatrixX3d T = fx.candidates(2, 6);
  TranslationCostProblem pb;
  pb.points = P;
  pb.point_normals = NP;
  pb.lambda = 1.0 / fx.cell;
  pb.offsets = T;
  const Eigen::VectorXd costs = cpu.evaluate(grid, pb);
  MatchingOptions options;
  options.lambda = pb.lambda;
  options.epsilon = 1.0;
  options.refine_to = 0;
  auto pick = [&](uint64_t seed) {
    std::mt19937_64 rng(seed);
    return choose_offset(grid, cpu, P, NP, T, Vector2d(2, 2) * fx.cell, Vector2d(6, 6) * fx.cell,
                         fx.cell, options, rng);
  };
  std::set<std::pair<double, double>> distinct;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    const OffsetChoice a = pick(seed), b = pick(seed);
    EXPECT_EQ(a.offset, b.offset) << "seed " << seed;  // same seed, same choice
    EXPECT_LE(a.cost, (1 + options.epsilon) * costs.minCoeff() * (1 + 1e-12));
    distinct.insert({a.offset.x(), a.offset.y()});
  }
  EXPECT_GE(distinct.size(), 2u) << "epsilon > 0 never varied the choice";
}

TEST(GeometryMatching, EdgeCases) {
  const PeriodicFixture fx;
  const SwatchFaceTree grid(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  std::mt19937_64 rng(1);
  MatchingOptions options;
  MatrixX3d P, NP;
  fx.subpatch(2.0, 4.0, 1.5, 3.0, Vector3d::Zero(), P, NP);
  EXPECT_THROW(choose_offset(grid, cpu, P, NP, MatrixX3d(0, 3), Vector2d(0, 0), Vector2d(1, 1),
                             fx.cell, options, rng),
               InvalidInput);
  // No output points: the first admissible placement.
  const MatrixX3d T = fx.candidates(1, 3);
  const OffsetChoice c = choose_offset(grid, cpu, MatrixX3d(0, 3), MatrixX3d(0, 3), T,
                                       Vector2d(0, 0), Vector2d(3, 3), fx.cell, options, rng);
  EXPECT_EQ(c.offset, Vector3d(T.row(0).transpose()));
}

}  // namespace
}  // namespace mq

namespace mq {
namespace {

// A sub-patch taken from an apple layer itself, mirrored and shifted: close to the swatch,
// never on it; 25 whole-cell candidates around zero.
struct MirroredApples {
  TriMesh swatch;
  MatrixX3d P, NP, T;
  double cell = 0;
  MirroredApples() {
    AppleOptions apples;
    apples.count = 9;
    swatch = apple_layer(apples);
    const BoundingBox box = bounding_box(swatch.V, swatch.F);
    const Vector3d mid = 0.5 * (box.min + box.max);
    const MatrixX3d FN = face_normals(swatch.V, swatch.F);
    std::vector<Vector3d> points, normals;
    for (int f = 0; f < swatch.num_faces(); f += 3) {
      Vector3d c = (swatch.V.row(swatch.F(f, 0)) + swatch.V.row(swatch.F(f, 1)) +
                    swatch.V.row(swatch.F(f, 2)))
                       .transpose() /
                   3.0;
      if ((c - mid).head<2>().norm() > 0.3 * (box.max - box.min).head<2>().norm()) continue;
      c.x() = 2 * mid.x() - c.x();
      points.push_back(c + Vector3d(0.13, -0.07, 0));
      normals.push_back(Vector3d(-FN(f, 0), FN(f, 1), FN(f, 2)));
    }
    P.resize(static_cast<Eigen::Index>(points.size()), 3);
    NP.resize(P.rows(), 3);
    for (size_t i = 0; i < points.size(); ++i) {
      P.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
      NP.row(static_cast<Eigen::Index>(i)) = normals[i].transpose();
    }
    cell = 0.25 * (box.max - box.min).head<2>().minCoeff();
    T.resize(25, 3);
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) T.row(j * 5 + i) << (i - 2) * cell, (j - 2) * cell, 0.0;
  }
};

// The sub-cell refinement reports the exact Eq. (3) cost of the offset it returns, and that
// cost is never above the cost of the whole-cell offset it started from (each accepted
// majorize-minimize round lowers the exact cost), on a swatch with no exact match.
TEST(GeometryMatching, RefinementLowersTheExactCost) {
  const MirroredApples fx;
  const TriMesh& swatch = fx.swatch;
  const MatrixX3d &P = fx.P, &NP = fx.NP, &T = fx.T;
  const double cell = fx.cell;
  ASSERT_GT(P.rows(), 20);
  const SwatchFaceTree tree(swatch.V, swatch.F);
  TranslationCostCpu cpu;
  MatchingOptions options;
  options.lambda = 1.0 / cell;
  options.refine_points = P.rows();  // refine on every point, so the costs are comparable
  options.screen_keep = 0;
  std::mt19937_64 rng(1);
  const Vector2d lo(-2 * cell, -2 * cell), hi(2 * cell, 2 * cell);
  const OffsetChoice refined = choose_offset(tree, cpu, P, NP, T, lo, hi, cell, options, rng);
  options.refine_to = 0;
  const OffsetChoice whole = choose_offset(tree, cpu, P, NP, T, lo, hi, cell, options, rng);
  EXPECT_NE(refined.offset, whole.offset);
  EXPECT_GT(refined.evaluations, whole.evaluations);

  TranslationCostProblem problem;
  problem.points = P;
  problem.point_normals = NP;
  problem.lambda = options.lambda;
  problem.offsets.resize(2, 3);
  problem.offsets.row(0) = refined.offset.transpose();
  problem.offsets.row(1) = whole.offset.transpose();
  const Eigen::VectorXd E = translation_cost_brute_force(swatch.V, swatch.F, problem);
  EXPECT_NEAR(refined.cost, E(0), 1e-9 * E(0));
  EXPECT_NEAR(whole.cost, E(1), 1e-9 * E(1));
  EXPECT_LT(E(0), E(1));
  for (int k = 0; k < 2; ++k) {  // inside the admissible range
    EXPECT_GE(refined.offset(k), lo(k));
    EXPECT_LE(refined.offset(k), hi(k));
  }
}

// When refining, the finalists are scored on the refinement's strided subset: choosing with
// all the points equals choosing with that subset alone, and the reported cost is the subset's
// exact Eq. (3) cost at the returned offset.
TEST(GeometryMatching, FinalistsAreScoredOnTheRefinementSubset) {
  const MirroredApples fx;
  ASSERT_GT(fx.P.rows(), 40);
  const SwatchFaceTree tree(fx.swatch.V, fx.swatch.F);
  TranslationCostCpu cpu;
  MatchingOptions options;
  options.lambda = 1.0 / fx.cell;
  options.refine_points = 16;
  options.screen_keep = 0;  // every candidate is a finalist
  const Eigen::Index n = options.refine_points;
  MatrixX3d Ps(n, 3), Ns(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    Ps.row(i) = fx.P.row(i * fx.P.rows() / n);
    Ns.row(i) = fx.NP.row(i * fx.P.rows() / n);
  }
  std::mt19937_64 rng(1);
  const Vector2d lo(-2 * fx.cell, -2 * fx.cell), hi(2 * fx.cell, 2 * fx.cell);
  const OffsetChoice all =
      choose_offset(tree, cpu, fx.P, fx.NP, fx.T, lo, hi, fx.cell, options, rng);
  const OffsetChoice subset = choose_offset(tree, cpu, Ps, Ns, fx.T, lo, hi, fx.cell, options, rng);
  EXPECT_EQ(all.offset, subset.offset);
  EXPECT_EQ(all.cost, subset.cost);
  EXPECT_EQ(all.point_offsets, subset.point_offsets);  // no evaluation used the other points
  TranslationCostProblem problem;
  problem.points = Ps;
  problem.point_normals = Ns;
  problem.lambda = options.lambda;
  problem.offsets = all.offset.transpose();
  const Eigen::VectorXd E = translation_cost_brute_force(fx.swatch.V, fx.swatch.F, problem);
  EXPECT_NEAR(all.cost, E(0), 1e-9 * E(0));
  // Without refinement every point counts: the reported cost is the all-points cost.
  options.refine_to = 0;
  const OffsetChoice whole =
      choose_offset(tree, cpu, fx.P, fx.NP, fx.T, lo, hi, fx.cell, options, rng);
  problem.points = fx.P;
  problem.point_normals = fx.NP;
  problem.offsets = whole.offset.transpose();
  const Eigen::VectorXd W = translation_cost_brute_force(fx.swatch.V, fx.swatch.F, problem);
  EXPECT_NEAR(whole.cost, W(0), 1e-9 * W(0));
}

}  // namespace
}  // namespace mq
