#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <random>

#include "core/errors.h"
#include "core/geometry_measures.h"
#include "core/point_triangle.h"
#include "core/translation_cost.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Uniform in [lo, hi) from the raw engine output (portable across standard libraries).
double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * double(rng() >> 11) * 0x1.0p-53;
}

// Reference Eq. (2) for one query point: the minimum over every face.
double min_face_cost_reference(const MatrixX3d& V, const MatrixX3i& F, const Vector3d& q,
                               const Vector3d& n, double lambda) {
  const MatrixX3d FN = face_normals(V, F);
  double best = std::numeric_limits<double>::infinity();
  for (int f = 0; f < F.rows(); ++f) {
    const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const double d = std::sqrt(point_triangle_squared_distance<double>(q, a, b, c));
    best = std::min(best, (1 + lambda * d) * (1 + (n - Vector3d(FN.row(f))).norm()));
  }
  return best;
}

TEST(TranslationCost, BruteForceMatchesHandComputedValues) {
  // One triangle in z = 0; the point sits 2 above its interior after the offset is undone.
  MatrixX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  MatrixX3i F(1, 3);
  F << 0, 1, 2;  // normal +z
  TranslationCostProblem pb;
  pb.points.resize(2, 3);
  pb.points << 0.25, 0.25, 2.0, 5.25, 0.25, 2.0;
  pb.point_normals.resize(2, 3);
  pb.point_normals << 0, 0, 1, 0, 0, -1;
  pb.offsets.resize(2, 3);
  pb.offsets << 0, 0, 0, 5, 0, 0;
  pb.lambda = 0.5;
  const Eigen::VectorXd E = translation_cost_brute_force(V, F, pb);
  ASSERT_EQ(E.size(), 2);
  // t = 0: point 0 above the interior (dist 2, same normal: 2 * 1); point 1 is nearest to
  // vertex (1, 0, 0), offset (4.25, 0.25, 2), opposite normal (factor 3).
  const double d1 = std::sqrt(4.25 * 4.25 + 0.25 * 0.25 + 4.0);
  EXPECT_NEAR(E(0), (1 + 0.5 * 2) * 1 + (1 + 0.5 * d1) * 3, 1e-12);
  // t = (5, 0, 0): point 0 becomes (-4.75, 0.25, 2), nearest to edge x = 0 at (0, 0.25, 0).
  const double d0 = std::sqrt(4.75 * 4.75 + 4.0);
  EXPECT_NEAR(E(1), (1 + 0.5 * d0) * 1 + (1 + 0.5 * 2) * 3, 1e-12);
}

TEST(TranslationCost, GridQueryIsExactEverywhere) {
  // Points inside, near and far outside the grid, several lambdas and cell sizes.
  const TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  std::mt19937_64 rng(7);
  for (double cell : {0.0, 0.13, 1.7}) {
    const SwatchDistanceGrid grid(torus.V, torus.F, cell);
    if (cell > 0) {
      EXPECT_DOUBLE_EQ(grid.cell_size(), cell);
    }
    for (double lambda : {0.0, 1.0, 4.0}) {
      for (int i = 0; i < 40; ++i) {
        const double r = i < 20 ? 3.0 : 30.0;
        const Vector3d q(uniform(rng, -r, r), uniform(rng, -r, r), uniform(rng, -r, r));
        const Vector3d n = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), 0.3).normalized();
        const double expected = min_face_cost_reference(torus.V, torus.F, q, n, lambda);
        EXPECT_NEAR(grid.min_face_cost(q, n, lambda), expected, 1e-12 * expected)
            << "cell " << cell << " lambda " << lambda << " q " << q.transpose();
      }
    }
  }
}

TEST(TranslationCost, GridBinsEveryFace) {
  const TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  const SwatchDistanceGrid grid(torus.V, torus.F);
  EXPECT_EQ(grid.num_faces(), torus.num_faces());
  EXPECT_LE(grid.num_cells(), 2 * torus.num_faces() + 64);
  EXPECT_EQ(grid.cell_start().size(), std::size_t(grid.num_cells()) + 1);
  std::vector<int> seen(torus.num_faces(), 0);
  for (int f : grid.cell_faces()) ++seen[f];
  for (int f = 0; f < torus.num_faces(); ++f) EXPECT_GT(seen[f], 0) << "face " << f;
  // The fingerprint follows the content.
  EXPECT_EQ(grid.fingerprint(), SwatchDistanceGrid(torus.V, torus.F).fingerprint());
  EXPECT_NE(grid.fingerprint(), SwatchDistanceGrid(torus.V, torus.F, 0.3).fingerprint());
}

TEST(TranslationCost, BestOffsetTieRule) {
  Eigen::VectorXd c(4);
  c << 3.0, 2.0, 2.0 * (1 + 5e-7), 2.0;
  EXPECT_EQ(best_offset(c), 1);
  c << 3.0, 2.0 * (1 + 5e-7), 2.0, 2.5;
  EXPECT_EQ(best_offset(c), 0 + 1);  // within 1e-6 of the minimum: smaller index wins
  c << 3.0, 2.0 * (1 + 5e-6), 2.0, 2.5;
  EXPECT_EQ(best_offset(c), 2);  // clearly larger: the true minimum wins
  EXPECT_THROW(best_offset(Eigen::VectorXd()), InvalidInput);
  c(0) = std::nan("");
  EXPECT_THROW(best_offset(c), InvalidInput);
}

TEST(TranslationCost, InvalidGridInputThrows) {
  const TriMesh cube = test::unit_cube();
  EXPECT_THROW(SwatchDistanceGrid(cube.V, MatrixX3i(0, 3)), InvalidInput);
  MatrixX3i badF = cube.F;
  badF(3, 1) = 8;
  EXPECT_THROW(SwatchDistanceGrid(cube.V, badF), InvalidInput);
  MatrixX3d badV = cube.V;
  badV(2, 0) = std::nan("");
  EXPECT_THROW(SwatchDistanceGrid(badV, cube.F), InvalidInput);
  EXPECT_THROW(SwatchDistanceGrid(cube.V, cube.F, -1.0), InvalidInput);
  EXPECT_THROW(SwatchDistanceGrid(cube.V, cube.F, 1e-6), InvalidInput);  // 10^18 cells
}

TEST(TranslationCost, CpuIsIndependentOfThreadCount) {
  const TriMesh torus = test::torus(2.0, 0.5, 32, 16);
  const MatrixX3d N = vertex_normals(torus.V, torus.F);
  TranslationCostProblem pb;
  pb.points = torus.V.topRows(100);
  pb.point_normals = N.topRows(100);
  pb.offsets.resize(9, 3);
  for (int i = 0; i < 9; ++i) pb.offsets.row(i) << 0.1 * (i % 3), 0.1 * (i / 3), 0.0;
  const SwatchDistanceGrid grid(torus.V, torus.F);
  TranslationCostCpu cpu;
  Eigen::VectorXd one, two;
  tbb::task_arena(1).execute([&] { one = cpu.evaluate(grid, pb); });
  tbb::task_arena(2).execute([&] { two = cpu.evaluate(grid, pb); });
  ASSERT_EQ(one.size(), 9);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(one(i), two(i)) << "offset " << i;
  // The grid's pruning is exact and sums in the same order: bitwise equal to brute force.
  const Eigen::VectorXd brute = translation_cost_brute_force(torus.V, torus.F, pb);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(one(i), brute(i)) << "offset " << i;
  // Zero offset puts every point on the swatch: the smallest cost.
  EXPECT_EQ(best_offset(one), 0);
}

}  // namespace
}  // namespace mq
