// Offset surface (paper section 3.2): a valid shell on real bases, heights lowered only where
// the surface is concave.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/shell/shell_tetrahedra.h"
#include "tests/core/shell_fixtures.h"

namespace mq {
namespace {

// The properties every offset must have.
void expect_valid_offset(const TriMesh& base, const OffsetOptions& opt, const OffsetSurface& o) {
  const int n = base.num_vertices();
  ASSERT_EQ(o.V.rows(), n);
  ASSERT_EQ(o.heights.size(), n);
  ASSERT_EQ(o.directions.rows(), n);
  const MatrixX3d N = vertex_normals(base.V, base.F);
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(o.directions.row(i).norm(), 1.0, 1e-12) << "vertex " << i;
    EXPECT_GT(o.directions.row(i).dot(N.row(i)), 0.0) << "vertex " << i;
    EXPECT_GE(o.heights(i), opt.min_fraction * opt.height * (1 - 1e-12));
    EXPECT_LE(o.heights(i), opt.height);
    EXPECT_NEAR((o.V.row(i) - base.V.row(i) - o.heights(i) * o.directions.row(i)).norm(), 0.0,
                1e-12);
  }
  IntersectionOptions all;
  all.between_components_only = false;
  EXPECT_EQ(intersecting_face_pairs(o.V, base.F, all).size(), 0u);
  TetMesh shell;
  ASSERT_NO_THROW(shell = shell_tetrahedra(base.V, o.V, base.F));
  EXPECT_GT(tet_volumes(shell).minCoeff(), 0.0);
}

int num_shrunk(const OffsetOptions& opt, const OffsetSurface& o) {
  return static_cast<int>((o.heights.array() < opt.height).count());
}

TEST(OffsetSurface, ConvexSphereKeepsTheFullHeight) {
  const TriMesh s = test::icosphere(3);
  OffsetOptions opt;
  opt.height = 0.05;
  const OffsetSurface o = offset_surface(s.V, s.F, opt);
  expect_valid_offset(s, opt, o);
  EXPECT_EQ(num_shrunk(opt, o), 0);
  // The offset of a unit sphere along its (smoothed) normals is the sphere of radius 1 + h.
  for (int i = 0; i < s.num_vertices(); ++i) EXPECT_NEAR(o.V.row(i).norm(), 1.05, 1e-3);
}

TEST(OffsetSurface, FlatGridOffsetsStraightUp) {
  const TriMesh g = test::plane_grid(1.0, 1.0, 5, 5);
  OffsetOptions opt;
  opt.height = 0.1;
  const OffsetSurface o = offset_surface(g.V, g.F, opt);
  expect_valid_offset(g, opt, o);
  EXPECT_NEAR((o.V - g.V).col(2).minCoeff(), 0.1, 1e-12);
  EXPECT_NEAR(tet_volumes(shell_tetrahedra(g.V, o.V, g.F)).sum(), 0.1, 1e-12);
}

TEST(OffsetSurface, Bunny) {
  const test::OffsetBase ob = test::offset_base("base/bunny_igl_7k.off");
  expect_valid_offset(ob.base, ob.options, ob.offset);
}

TEST(OffsetSurface, KnightIsLoweredInConcaveRegionsOnly) {
  const test::OffsetBase ob = test::offset_base("base/knight_decimated_1k.off");
  expect_valid_offset(ob.base, ob.options, ob.offset);
  const int shrunk = num_shrunk(ob.options, ob.offset);
  EXPECT_GT(shrunk, 0);
  EXPECT_LT(shrunk, ob.base.num_vertices() / 2);
}

TEST(OffsetSurface, CupBaseFoldIsReported) {
  // cup_mug_11k folds over itself near the handle: vertex 5099 has a face pointing down among
  // faces pointing up, so no offset direction lies above all of them and every prism there
  // would be inverted at any height. The offset refuses with a TopologyError naming it.
  const TriMesh base = read_mesh(test::shared_data("base/cup_mug_11k.off"));
  OffsetOptions opt;
  opt.height = 0.02 * test::bbox_diagonal(base);
  try {
    offset_surface(base.V, base.F, opt);
    FAIL() << "expected a TopologyError";
  } catch (const TopologyError& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 5099"), std::string::npos) << e.what();
  }
  // Without the throw: the folded vertices and their faces.
  OffsetSurface out;
  OffsetFailure failure;
  EXPECT_FALSE(try_offset_surface(base.V, base.F, opt, out, failure));
  EXPECT_TRUE(failure.fold);
  EXPECT_TRUE(std::binary_search(failure.vertices.begin(), failure.vertices.end(), 5099));
  EXPECT_FALSE(failure.faces.empty());
}

TEST(OffsetSurface, ConcaveFoldIsLoweredConvexSideIsNot) {
  // A V-shaped valley: offsetting the two flanks by more than the valley allows makes their
  // offsets cross above the crease, so heights must drop there but stay full far away.
  TriMesh g = test::plane_grid(4.0, 1.0, 16, 4);
  for (int i = 0; i < g.num_vertices(); ++i) g.V(i, 2) = 1.5 * std::abs(g.V(i, 0) - 2.0);
  OffsetOptions opt;
  opt.height = 0.8;
  const OffsetSurface o = offset_surface(g.V, g.F, opt);
  expect_valid_offset(g, opt, o);
  for (int i = 0; i < g.num_vertices(); ++i) {
    if (std::abs(g.V(i, 0) - 2.0) < 1e-9) {
      EXPECT_LT(o.heights(i), opt.height);
    }
    if (std::abs(g.V(i, 0) - 2.0) > 1.5) {
      EXPECT_EQ(o.heights(i), opt.height);
    }
  }
  // The mirrored ridge is convex: nothing is lowered.
  TriMesh ridge = g;
  ridge.V.col(2) *= -1.0;
  const OffsetSurface r = offset_surface(ridge.V, ridge.F, opt);
  expect_valid_offset(ridge, opt, r);
  EXPECT_EQ(num_shrunk(opt, r), 0);
}

// The smoothing reaches as far over the surface whatever its tessellation: the real bunny and
// the same surface split 1-to-4 twice get nearly the same directions at the bunny's own
// vertices, where a fixed count of steps (smoothing_radius 0) reaches a quarter as far on the
// finer one and leaves its directions much closer to the raw normals (a 1M-face base split that
// way had no valid shell with the fixed count).
TEST(OffsetSurface, SmoothingDoesNotDependOnTheTessellation) {
  const TriMesh coarse = read_mesh(test::shared_data("base/bunny_igl_7k.off"));
  const TriMesh fine = test::midpoint_split(test::midpoint_split(coarse));
  OffsetOptions opt;
  opt.height = 0.04 * test::bbox_diagonal(coarse);
  opt.smoothing_iterations = 0;  // the radius alone sets the steps
  int coarse_steps = 0, fine_steps = 0;
  const MatrixX3d Dc = offset_directions(coarse.V, coarse.F, opt, &coarse_steps);
  const MatrixX3d Df = offset_directions(fine.V, fine.F, opt, &fine_steps);
  EXPECT_GE(coarse_steps, 4);
  EXPECT_NEAR(fine_steps, 16 * coarse_steps, 0.2 * fine_steps);  // edges a quarter as long (ceil)
  OffsetOptions fixed = opt;
  fixed.smoothing_radius = 0;
  fixed.smoothing_iterations = coarse_steps;
  const MatrixX3d Dfixed = offset_directions(fine.V, fine.F, fixed);
  double scaled = 0, unscaled = 0;
  const int n = coarse.num_vertices();
  for (int i = 0; i < n; ++i) {
    scaled += std::acos(std::clamp(Dc.row(i).dot(Df.row(i)), -1.0, 1.0));
    unscaled += std::acos(std::clamp(Dc.row(i).dot(Dfixed.row(i)), -1.0, 1.0));
  }
  scaled *= 180 / M_PI / n;
  unscaled *= 180 / M_PI / n;
  std::printf("mean angle to the coarse directions: %.2f deg scaled, %.2f deg fixed steps\n",
              scaled, unscaled);
  EXPECT_LT(scaled, 3.0);              // measured 1.3 degrees
  EXPECT_LT(scaled, 0.25 * unscaled);  // measured 12.6
}

TEST(OffsetSurface, IndependentOfThreadCount) {
  const TriMesh base = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  OffsetOptions opt;
  opt.height = 0.02 * test::bbox_diagonal(base);
  const OffsetSurface a = offset_surface(base.V, base.F, opt);
  OffsetSurface b;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    b = offset_surface(base.V, base.F, opt);
  }
  EXPECT_TRUE(a.V == b.V);
  EXPECT_TRUE(a.heights == b.heights);
}

TEST(OffsetSurface, ImpossibleShellThrows) {
  // A valley too narrow for even min_fraction of the height: the floor makes it unfixable.
  TriMesh g = test::plane_grid(4.0, 1.0, 16, 4);
  for (int i = 0; i < g.num_vertices(); ++i) g.V(i, 2) = 20.0 * std::abs(g.V(i, 0) - 2.0);
  OffsetOptions opt;
  opt.height = 5.0;
  opt.smoothing_iterations = 0;
  opt.min_fraction = 0.9;
  EXPECT_THROW(offset_surface(g.V, g.F, opt), TopologyError);
  // Without the throw: where (the offending prisms, here on both walls), and why.
  OffsetSurface out;
  OffsetFailure failure;
  EXPECT_FALSE(try_offset_surface(g.V, g.F, opt, out, failure));
  EXPECT_FALSE(failure.fold);
  EXPECT_NE(failure.reason.find("cannot make a valid shell"), std::string::npos);
  ASSERT_FALSE(failure.faces.empty());
  ASSERT_FALSE(failure.vertices.empty());
  EXPECT_TRUE(std::is_sorted(failure.faces.begin(), failure.faces.end()));
  // A valid shell: true, nothing reported.
  const TriMesh flat = test::plane_grid(4.0, 1.0, 16, 4);
  EXPECT_TRUE(try_offset_surface(flat.V, flat.F, opt, out, failure));
  EXPECT_TRUE(failure.faces.empty() && failure.reason.empty());
}

// The same faces as F but those listed (ascending) left out.
MatrixX3i faces_without(const MatrixX3i& F, const std::vector<int>& out) {
  std::vector<int> kept;
  for (int f = 0; f < F.rows(); ++f)
    if (!std::binary_search(out.begin(), out.end(), f)) kept.push_back(f);
  MatrixX3i K(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t i = 0; i < kept.size(); ++i) K.row(static_cast<Eigen::Index>(i)) = F.row(kept[i]);
  return K;
}

TEST(OffsetSurface, AnEarlierCallsPairsGiveTheSameShell) {
  // ShellMap's fallback: a failed shell, then the same vertices with regions left out (and, after
  // a fold repair, some vertices moved). With the first call's pairs passed on, each later call
  // must decide exactly as a call on its own: same heights, same success, same failure.
  TriMesh g = test::plane_grid(4.0, 1.0, 32, 8);  // a valley too narrow at its floor
  for (int i = 0; i < g.num_vertices(); ++i) g.V(i, 2) = 20.0 * std::abs(g.V(i, 0) - 2.0);
  OffsetOptions opt;
  opt.height = 5.0;
  opt.smoothing_iterations = 0;
  opt.min_fraction = 0.9;
  OffsetPairCache cache;
  OffsetSurface out;
  OffsetFailure failure;
  ASSERT_FALSE(try_offset_surface(g.V, g.F, opt, out, failure, &cache));
  ASSERT_GT(failure.faces.size(), 4u);
  ASSERT_EQ(cache.S.rows(), 2 * g.num_vertices());
  ASSERT_FALSE(cache.pairs.empty());  // the valley's walls meet: pairs to carry over
  const std::vector<int> all = failure.faces;
  const std::vector<int> half(all.begin(), all.begin() + static_cast<long>(all.size() / 2));
  MatrixX3d moved = g.V;
  moved.row(g.F(all.back(), 0)) += Vector3d(0.01, 0.0, 0.0).transpose();
  struct Case {
    MatrixX3d V;
    MatrixX3i F;
  };
  int kept_pairs = 0;
  for (const Case& c : {Case{g.V, faces_without(g.F, half)}, Case{g.V, faces_without(g.F, all)},
                        Case{moved, faces_without(g.F, half)}, Case{g.V, g.F}}) {
    kept_pairs += static_cast<int>(cache.pairs.size());
    OffsetSurface with, alone;
    OffsetFailure with_failure, alone_failure;
    const bool ok = try_offset_surface(c.V, c.F, opt, with, with_failure, &cache);
    ASSERT_EQ(ok, try_offset_surface(c.V, c.F, opt, alone, alone_failure));
    EXPECT_TRUE(with.heights == alone.heights);
    EXPECT_TRUE(with.V == alone.V);
    EXPECT_EQ(with_failure.reason, alone_failure.reason);
    EXPECT_EQ(with_failure.faces, alone_failure.faces);
    EXPECT_EQ(with_failure.vertices, alone_failure.vertices);
  }
  EXPECT_GT(kept_pairs, 0);
}

TEST(OffsetSurface, InvalidInputThrows) {
  const TriMesh s = test::icosphere(1);
  OffsetOptions opt;
  EXPECT_THROW(offset_surface(s.V, s.F, opt), InvalidInput);  // height 0
  opt.height = std::nan("");
  EXPECT_THROW(offset_surface(s.V, s.F, opt), InvalidInput);
  opt.height = 0.1;
  opt.min_fraction = 0.0;
  EXPECT_THROW(offset_surface(s.V, s.F, opt), InvalidInput);
  opt.min_fraction = 0.1;
  opt.smoothing_iterations = -1;
  EXPECT_THROW(offset_surface(s.V, s.F, opt), InvalidInput);
  opt.smoothing_iterations = 3;
  MatrixX3d V = s.V;
  V(0, 0) = std::nan("");
  EXPECT_THROW(offset_surface(V, s.F, opt), InvalidInput);
  MatrixX3i F = s.F;
  F(2, 2) = -1;
  EXPECT_THROW(offset_surface(s.V, F, opt), InvalidInput);
  EXPECT_THROW(offset_surface(s.V, MatrixX3i(0, 3), opt), InvalidInput);
  EXPECT_NO_THROW(offset_surface(s.V, s.F, opt));
}

TEST(OffsetSurface, OptionsValidate) {
  OffsetOptions opt;
  EXPECT_THROW(opt.validate(), InvalidInput);  // height 0
  EXPECT_NO_THROW(opt.validate_smoothing());   // offset_directions needs no height
  opt.height = 0.1;
  EXPECT_NO_THROW(opt.validate());
  opt.max_rounds = 0;
  EXPECT_THROW(opt.validate(), InvalidInput);
  opt.max_rounds = 1;
  opt.smoothing_radius = -1;
  EXPECT_THROW(opt.validate_smoothing(), InvalidInput);
  EXPECT_THROW(opt.validate(), InvalidInput);
}

}  // namespace
}  // namespace mq
