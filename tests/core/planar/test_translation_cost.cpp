#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <functional>
#include <numeric>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/point_triangle.h"
#include "core/planar/translation_cost.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Uniform in [lo, hi) from the raw engine output (portable across standard libraries).
using test::uniform;

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

TEST(TranslationCost, TreeQueryIsExactEverywhere) {
  // Points inside, near and far outside the swatch, several lambdas and leaf sizes.
  const TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  std::mt19937_64 rng(7);
  for (int leaf : {1, 4, 64, 10000}) {
    const SwatchFaceTree tree(torus.V, torus.F, leaf);
    for (double lambda : {0.0, 1.0, 4.0}) {
      for (int i = 0; i < 40; ++i) {
        const double r = i < 20 ? 3.0 : 30.0;
        const Vector3d q(uniform(rng, -r, r), uniform(rng, -r, r), uniform(rng, -r, r));
        const Vector3d n = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), 0.3).normalized();
        const double expected = min_face_cost_reference(torus.V, torus.F, q, n, lambda);
        EXPECT_NEAR(tree.min_face_cost(q, n, lambda), expected, 1e-12 * expected)
            << "leaf " << leaf << " lambda " << lambda << " q " << q.transpose();
      }
    }
  }
}

// The reported entry attains the minimum: its own cost (entry_cost) is bitwise the minimum,
// and its face's reference cost matches within rounding. The majorize-minimize refinement
// relies on both.
TEST(TranslationCost, TreeQueryReportsTheEntryAttainingTheMinimum) {
  const TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  const MatrixX3d FN = face_normals(torus.V, torus.F);
  std::mt19937_64 rng(11);
  for (int leaf : {1, 64}) {
    const SwatchFaceTree tree(torus.V, torus.F, leaf);
    for (double lambda : {0.0, 2.0}) {
      for (int i = 0; i < 40; ++i) {
        const double r = i < 20 ? 3.0 : 30.0;
        const Vector3d q(uniform(rng, -r, r), uniform(rng, -r, r), uniform(rng, -r, r));
        const Vector3d n = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), 0.3).normalized();
        int entry = -2;
        const double best = tree.min_face_cost(q, n, lambda, &entry);
        ASSERT_GE(entry, 0);
        ASSERT_LT(entry, tree.num_faces());
        EXPECT_EQ(tree.entry_cost(entry, q, n, lambda), best);
        EXPECT_EQ(tree.entry_cost_with_factor(entry, q, tree.entry_normal_factor(entry, n), lambda),
                  best);
        const int f = tree.entry_faces()[static_cast<size_t>(entry)];
        const Vector3d a = torus.V.row(torus.F(f, 0)), b = torus.V.row(torus.F(f, 1)),
                       c = torus.V.row(torus.F(f, 2));
        const double d = std::sqrt(point_triangle_squared_distance<double>(q, a, b, c));
        // The entry's face geometry as the tree hands it to callers (correspondences).
        const SwatchFaceTree::FacePoint on_face = tree.entry_closest_point(entry, q);
        EXPECT_EQ((q - on_face.point).norm(), d);
        EXPECT_NEAR((on_face.barycentric(0) * a + on_face.barycentric(1) * b +
                     on_face.barycentric(2) * c - on_face.point)
                        .norm(),
                    0.0, 1e-12);
        EXPECT_EQ(tree.entry_normal(entry), Vector3d(FN.row(f).transpose()));
        const double reference = (1 + lambda * d) * (1 + (n - Vector3d(FN.row(f))).norm());
        EXPECT_NEAR(reference, best, 1e-12 * best);
        EXPECT_NEAR(min_face_cost_reference(torus.V, torus.F, q, n, lambda), best, 1e-12 * best);
      }
    }
  }
}

// With a distance cap only faces within it compete: the result is the minimum over those faces
// (brute force), infinity with entry -1 when none is that near. Correspondences rely on it.
TEST(TranslationCost, TreeQueryWithADistanceCapRanksOnlyFacesWithinIt) {
  const TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  const MatrixX3d FN = face_normals(torus.V, torus.F);
  std::mt19937_64 rng(13);
  int capped = 0, empty = 0;
  for (int leaf : {1, 64}) {
    const SwatchFaceTree tree(torus.V, torus.F, leaf);
    for (double lambda : {0.0, 1.0}) {
      for (int i = 0; i < 60; ++i) {
        const Vector3d q(uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -1, 1));
        const Vector3d n = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), 0.3).normalized();
        const double cap = uniform(rng, 0.0, 0.6);
        double expected = std::numeric_limits<double>::infinity();
        for (int f = 0; f < torus.num_faces(); ++f) {
          const Vector3d a = torus.V.row(torus.F(f, 0)), b = torus.V.row(torus.F(f, 1)),
                         c = torus.V.row(torus.F(f, 2));
          const double d2 = point_triangle_squared_distance<double>(q, a, b, c);
          if (d2 > cap * cap) continue;
          expected = std::min(
              expected, (1 + lambda * std::sqrt(d2)) * (1 + (n - Vector3d(FN.row(f))).norm()));
        }
        int entry = -2;
        const double got = tree.min_face_cost(q, n, lambda, &entry, cap);
        if (std::isinf(expected)) {
          ++empty;
          EXPECT_TRUE(std::isinf(got));
          EXPECT_EQ(entry, -1);
          continue;
        }
        ++capped;
        ASSERT_GE(entry, 0);
        EXPECT_NEAR(got, expected, 1e-12 * expected) << "q " << q.transpose() << " cap " << cap;
        EXPECT_GE(got, tree.min_face_cost(q, n, lambda));  // never below the uncapped minimum
      }
    }
  }
  // Both outcomes occurred, so the test covers them.
  EXPECT_GT(capped, 20);
  EXPECT_GT(empty, 20);
}

TEST(TranslationCost, TreeHoldsEveryFaceOnceInBoundedLeaves) {
  const TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  const int leaf = 8;
  const SwatchFaceTree tree(torus.V, torus.F, leaf);
  EXPECT_EQ(tree.num_faces(), torus.num_faces());
  std::vector<int> seen(torus.num_faces(), 0);
  for (int f : tree.entry_faces()) ++seen[f];
  for (int f = 0; f < torus.num_faces(); ++f) EXPECT_EQ(seen[f], 1) << "face " << f;
  // Leaves partition the entries in order, hold at most `leaf` faces, and every node's box and
  // normal cone hold all faces below it; median splits keep the tree balanced.
  const std::vector<int>& links = tree.node_links();
  int next_entry = 0;
  for (int i = 0; i < tree.num_nodes(); ++i) {
    if (links[2 * i] >= 0) continue;
    EXPECT_EQ(-1 - links[2 * i], next_entry);
    EXPECT_LE(links[2 * i + 1], leaf);
    EXPECT_GE(links[2 * i + 1], 1);
    next_entry += links[2 * i + 1];
  }
  EXPECT_EQ(next_entry, torus.num_faces());
  std::function<void(int, std::vector<int>&)> faces_below = [&](int i, std::vector<int>& out) {
    if (links[2 * i] < 0) {
      for (int j = -1 - links[2 * i]; j < -1 - links[2 * i] + links[2 * i + 1]; ++j)
        out.push_back(j);
      return;
    }
    faces_below(i + 1, out);
    faces_below(links[2 * i], out);
  };
  for (int i = 0; i < tree.num_nodes(); i += 7) {
    std::vector<int> entries;
    faces_below(i, entries);
    const double* box = &tree.node_boxes()[8 * i];
    const double* cone = &tree.node_cones()[4 * i];
    for (const int j : entries) {
      for (int k = 0; k < 9; ++k)
        EXPECT_TRUE(tree.entry_triangles()[9 * j + k] >= box[k % 3] &&
                    tree.entry_triangles()[9 * j + k] <= box[4 + k % 3]);
      const Vector3d nf(&tree.entry_normals()[4 * j]);
      EXPECT_LE((nf - Vector3d(cone)).norm(), cone[3]);
    }
  }
  EXPECT_LE(tree.depth(), static_cast<int>(std::ceil(std::log2(torus.num_faces() / 4.0))) + 1);
  // The fingerprint follows the content.
  EXPECT_EQ(tree.fingerprint(), SwatchFaceTree(torus.V, torus.F, leaf).fingerprint());
  EXPECT_NE(tree.fingerprint(), SwatchFaceTree(torus.V, torus.F, 16).fingerprint());
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

TEST(TranslationCost, InvalidTreeInputThrows) {
  const TriMesh cube = test::unit_cube();
  EXPECT_THROW(SwatchFaceTree(cube.V, MatrixX3i(0, 3)), InvalidInput);
  MatrixX3i badF = cube.F;
  badF(3, 1) = 8;
  EXPECT_THROW(SwatchFaceTree(cube.V, badF), InvalidInput);
  MatrixX3d badV = cube.V;
  badV(2, 0) = std::nan("");
  EXPECT_THROW(SwatchFaceTree(badV, cube.F), InvalidInput);
  EXPECT_THROW(SwatchFaceTree(cube.V, cube.F, 0), InvalidInput);
}

// The first n vertices of a torus, with their normals, as the points of a problem (offsets to
// be set).
TranslationCostProblem torus_vertex_problem(const TriMesh& torus, int n) {
  TranslationCostProblem pb;
  pb.points = torus.V.topRows(n);
  pb.point_normals = vertex_normals(torus.V, torus.F).topRows(n);
  return pb;
}

TEST(TranslationCost, CpuIsIndependentOfThreadCount) {
  const TriMesh torus = test::torus(2.0, 0.5, 32, 16);
  TranslationCostProblem pb = torus_vertex_problem(torus, 100);
  pb.offsets.resize(9, 3);
  for (int i = 0; i < 9; ++i) {
    const int row = i / 3;  // a 3 x 3 grid of offsets
    pb.offsets.row(i) << 0.1 * (i % 3), 0.1 * row, 0.0;
  }
  const SwatchFaceTree tree(torus.V, torus.F);
  TranslationCostCpu cpu;
  Eigen::VectorXd one, two;
  tbb::task_arena(1).execute([&] { one = cpu.evaluate(tree, pb); });
  tbb::task_arena(2).execute([&] { two = cpu.evaluate(tree, pb); });
  ASSERT_EQ(one.size(), 9);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(one(i), two(i)) << "offset " << i;
  // The tree's pruning is exact and sums in the same order: bitwise equal to brute force.
  const Eigen::VectorXd brute = translation_cost_brute_force(torus.V, torus.F, pb);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(one(i), brute(i)) << "offset " << i;
  // Zero offset puts every point on the swatch: the smallest cost.
  EXPECT_EQ(best_offset(one), 0);
}

// A hint only starts the search: the minimum is bitwise the one found without it, and the
// entry reported attains it, whatever entry is hinted (near, far, or the minimiser itself).
TEST(TranslationCost, TreeQueryHintChangesNoMinimum) {
  const TriMesh torus = test::torus(2.0, 0.5, 24, 12);
  std::mt19937_64 rng(17);
  int hinted_minimiser = 0;
  for (int leaf : {1, 64}) {
    const SwatchFaceTree tree(torus.V, torus.F, leaf);
    for (double lambda : {0.0, 1.0, 3.0}) {
      for (int i = 0; i < 60; ++i) {
        const Vector3d q(uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -1.5, 1.5));
        const Vector3d n = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), 0.3).normalized();
        const double cap = i % 3 == 0 ? uniform(rng, 0.0, 0.8) : kInf;
        int plain_entry = -2;
        const double plain = tree.min_face_cost(q, n, lambda, &plain_entry, cap);
        const int hints[] = {static_cast<int>(rng() % static_cast<unsigned>(tree.num_faces())),
                             std::max(plain_entry, 0), tree.num_faces() - 1};
        for (const int hint : hints) {
          hinted_minimiser += hint == plain_entry;
          int entry = -2;
          const double hinted = tree.min_face_cost(q, n, lambda, &entry, cap, hint);
          EXPECT_EQ(hinted, plain) << "hint " << hint;
          if (std::isinf(plain)) {
            EXPECT_EQ(entry, -1);
          } else {
            ASSERT_GE(entry, 0);
            EXPECT_EQ(tree.entry_cost(entry, q, n, lambda), plain);
          }
        }
      }
    }
  }
  EXPECT_GT(hinted_minimiser, 100);
}

// The screening shortcut keeps exactly the offsets a stable sort of every cost keeps, on any
// thread count, and it does skip work when some offsets are clearly worse.
TEST(TranslationCost, CpuLeastCostOffsetsAreThoseOfSortingEveryCost) {
  const TriMesh torus = test::torus(2.0, 0.5, 32, 16);
  TranslationCostProblem pb = torus_vertex_problem(torus, 40);
  // 7 x 7 offsets around zero, the last rows repeating earlier ones: exact ties.
  pb.offsets.resize(56, 3);
  for (int i = 0; i < 49; ++i) {
    const int row = i / 7;
    pb.offsets.row(i) << 0.3 * (i % 7 - 3), 0.3 * (row - 3), 0.0;
  }
  for (int i = 49; i < 56; ++i) pb.offsets.row(i) = pb.offsets.row((i - 49) * 7 + 3);
  const SwatchFaceTree tree(torus.V, torus.F);
  TranslationCostCpu cpu;
  const Eigen::VectorXd costs = cpu.evaluate(tree, pb);
  for (const int keep : {1, 3, 7, 20}) {
    SCOPED_TRACE(keep);
    std::vector<int> expected(56);
    std::iota(expected.begin(), expected.end(), 0);
    std::stable_sort(expected.begin(), expected.end(),
                     [&](int a, int b) { return costs(a) < costs(b); });
    expected.resize(static_cast<size_t>(keep));
    std::sort(expected.begin(), expected.end());
    TranslationCostEvaluator::LeastCostOffsets one, two;
    tbb::task_arena(1).execute([&] { one = cpu.least_cost_offsets(tree, pb, keep); });
    tbb::task_arena(2).execute([&] { two = cpu.least_cost_offsets(tree, pb, keep); });
    EXPECT_EQ(one.kept, expected);
    EXPECT_EQ(two.kept, expected);
    EXPECT_EQ(one.point_offsets, two.point_offsets);
    EXPECT_GT(one.point_offsets, 0);
    EXPECT_LT(one.point_offsets, 40 * 56);  // far offsets were dropped part-way
    // The shared default (evaluate every pair, then sort) keeps the same offsets.
    EXPECT_EQ(cpu.TranslationCostEvaluator::least_cost_offsets(tree, pb, keep).kept, expected);
  }
  // No more offsets than kept: all of them, nothing evaluated.
  TranslationCostProblem few = pb;
  few.offsets = pb.offsets.topRows(3);
  const auto all = cpu.least_cost_offsets(tree, few, 3);
  EXPECT_EQ(all.kept, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(all.point_offsets, 0);
  EXPECT_THROW(cpu.least_cost_offsets(tree, pb, 0), InvalidInput);
}

}  // namespace
}  // namespace mq
