#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "core/planar/translation_cost.h"
#include "core/shell/quilt_embedding.h"
#include "core/structure/texture_structure.h"
#include "core/surface/surface_quilting.h"
#include "tests/core/planar_checks.h"
#include "tests/core/shell_fixtures.h"
#include "tests/slow/surface_checks.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(SurfaceQuilting, InvalidParametersThrow) {
  const TriMesh base = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  TranslationCostCpu cost;
  SurfaceQuiltingOptions o;
  o.scale = 0;
  EXPECT_THROW(quilt_surface(base, test::tiny_chainmail(), o, cost), InvalidInput);
  o.scale = std::nan("");
  EXPECT_THROW(quilt_surface(base, test::tiny_chainmail(), o, cost), InvalidInput);
  o.scale = 0.2;
  o.field = MatrixX3d::Zero(3, 3);
  EXPECT_THROW(quilt_surface(base, test::tiny_chainmail(), o, cost), InvalidInput);
  o.field.resize(0, 3);
  o.proxy_error = -1;
  EXPECT_THROW(quilt_surface(base, test::tiny_chainmail(), o, cost), InvalidInput);
  o.proxy_error = 0.05;
  o.proxy_min_faces = -1;
  EXPECT_THROW(quilt_surface(base, test::tiny_chainmail(), o, cost), InvalidInput);
  o.proxy_min_faces = 200'000;
  TriMesh nan_base = base;
  nan_base.V(0, 0) = std::nan("");
  EXPECT_THROW(quilt_surface(nan_base, test::tiny_chainmail(), o, cost), InvalidInput);
  EXPECT_THROW(quilt_surface(TriMesh(), test::tiny_chainmail(), o, cost), InvalidInput);
}

TEST(SurfaceQuilting, LocalCoordinatesMapBackToTheInputBase) {
  // A point given on the refined base and converted to the input base is the same 3D point.
  const TriMesh base = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  SurfaceQuilt quilt;
  quilt.input_base = base;
  quilt.base = bisect_longest_edges(base, 0.2 * mean_edge_length(base.V, base.F), 1 << 22,
                                    &quilt.refinement);
  ASSERT_GT(quilt.base.num_faces(), 20 * base.num_faces());
  test::expect_same_points_on_coarse(
      quilt.base, base, 97, [&quilt](int& face, Vector3d& b) { to_input_base(quilt, face, b); });
}

// Apples quilted by the local patches on a sphere of radius 3, embedded by normal displacement
// (the patches decide the sizes; the shell map is tested on its own): each element's size
// on the cap above z = 0.3 R (top) and the cap below -0.3 R (bottom), two caps of equal area.
struct CapSizes {
  std::vector<double> top, bottom;
  double coverage = 0;
  bool intersecting = false, within_shell = true;
};

CapSizes apples_on_caps(const Eigen::VectorXd& size_map) {
  TriMesh base = test::icosphere(3);
  base.V *= 3.0;
  AppleOptions ao;
  ao.count = 12;
  ao.resolution = 8;
  // Apples of one size: a cap's median is then its apples' size, not which of the swatch's
  // sizes the patches happened to put there (they differ by the compiler's rounding).
  ao.radius_variation = 0;
  const TriMesh swatch = apple_layer(ao);
  SurfaceQuiltingOptions o;
  o.scale = 0.2;
  o.size_map = size_map;
  const test::SurfaceRun run = test::run_surface(base, swatch, o, false);
  CapSizes r;
  r.coverage = run.embedding_stats.coverage;
  r.intersecting = !intersecting_face_pairs(run.output.V, run.output.F).empty();
  for (const SurfaceElement& el : run.quilt.elements)
    r.within_shell &= el.height.maxCoeff() <= run.quilt.shell_height * (1 + 1e-12);
  const StructureSummary s = summarize_structure(run.output, swatch, &base, run.stats.swatch_scale);
  for (const ElementStructure& el : s.output.elements) {
    const double z = el.centre.z() / el.centre.norm();
    if (z > 0.24) r.top.push_back(el.size);
    if (z < -0.24) r.bottom.push_back(el.size);
  }
  return r;
}

// A size map under the local patches (issue 25): each patch is flattened at its seed's size, so
// the apples over the sphere's top are half the size of those over its bottom (without the map
// the same), and four times as many there, whole and apart.
TEST(SurfaceQuilting, SizeMapSizesThePatchesElements) {
  const TriMesh base = test::icosphere(3);
  // Half size above z = 0.3 R, whole below -0.3 R, a ramp between (the icosphere's unit radius).
  Eigen::VectorXd map(base.num_vertices());
  for (int v = 0; v < base.num_vertices(); ++v)
    map(v) = 1.0 - 0.5 * std::clamp((base.V(v, 2) + 0.3) / 0.6, 0.0, 1.0);
  const CapSizes plain = apples_on_caps(Eigen::VectorXd()), sized = apples_on_caps(map);
  ASSERT_GT(plain.top.size(), 10u);
  ASSERT_GT(sized.bottom.size(), 10u);
  const double sized_ratio = test::median(sized.top) / test::median(sized.bottom);
  const double plain_ratio = test::median(plain.top) / test::median(plain.bottom);
  const double per_area =
      static_cast<double>(sized.top.size()) / static_cast<double>(sized.bottom.size());
  std::printf(
      "[ measure  ] patches with a size map on a sphere: apples on the top / bottom cap %zu / "
      "%zu (%zu / %zu without it); median apple on the top over the bottom's %.3f (0.5 wanted), "
      "%.3f without the map; %.1f%% covered\n",
      sized.top.size(), sized.bottom.size(), plain.top.size(), plain.bottom.size(), sized_ratio,
      plain_ratio, 100 * sized.coverage);
  EXPECT_NEAR(sized_ratio / 0.5, 1.0, 0.1);
  EXPECT_NEAR(plain_ratio, 1.0, 0.1);
  // Caps of equal area: half the size, four times the apples (within a third).
  EXPECT_GT(per_area, 4.0 / 1.33);
  EXPECT_LT(per_area, 4.0 * 1.33);
  EXPECT_GE(sized.coverage, 0.9);
  EXPECT_FALSE(sized.intersecting);
  EXPECT_TRUE(sized.within_shell);
}

// Apples (elements as tall as they are wide) by the local patches on a flat sheet fill it as the
// swatch is filled: a face counted covered within 1.5 shell heights of an apple left a band most
// of an apple wide around each patch where no later patch was seeded, and the swatch's own gaps
// at its border became bare streaks (here 78% of the swatch's density by the Voronoi cells and
// 98% of its apples per footprint area, against 90% and 113% now; the plane quilted from the
// same swatch reaches 99% and 109%). The apples stay apart.
TEST(SurfaceQuilting, TallElementsLeaveNoStreaksBetweenPatches) {
  const TriMesh base = test::plane_grid(3.0, 3.0, 24, 24);
  const TriMesh swatch = test::small_apples(11);
  const test::SurfaceRun run = test::run_surface(base, swatch, 0.13, false);
  const TriMesh& out = run.output;
  const double scale = run.stats.swatch_scale;
  const StructureSummary s = summarize_structure(out, swatch, &base, scale);
  // The swatch's apples per footprint area at the output's scale, against the apples whose
  // centre lies an apple or more inside the sheet's border per that inner area.
  const Vector3d lo = swatch.V.colwise().minCoeff(), hi = swatch.V.colwise().maxCoeff();
  const double per_area = 11.0 / ((hi - lo).x() * (hi - lo).y()) / (scale * scale);
  const double inset = s.output.median_size;
  int inside = 0;
  for (const ElementStructure& el : s.output.elements)
    inside += el.centre.x() > inset && el.centre.y() > inset && el.centre.x() < 3.0 - inset &&
              el.centre.y() < 3.0 - inset;
  const double counted = inside / ((3.0 - 2 * inset) * (3.0 - 2 * inset)) / per_area;
  std::printf(
      "[ measure  ] apples of 11 on a flat sheet by the patches: %d elements, %.1f%% of the "
      "swatch's density (Voronoi cells), %.1f%% of its apples per footprint area\n",
      static_cast<int>(s.output.elements.size()), 100 * s.comparison.density_ratio, 100 * counted);
  EXPECT_GE(s.comparison.density_ratio, 0.82);
  EXPECT_GE(counted, 1.05);
  EXPECT_TRUE(intersecting_face_pairs(out.V, out.F).empty());
}

// A base far finer than the texture (issue 14) is simplified before quilting: a gently curved
// sheet of 211,200 faces under a swatch a tenth of its size becomes a few thousand faces, its
// vertices on the sheet, within the error asked; the guidance given per input face follows its
// faces; --no-proxy (proxy_min_faces 0) keeps the base as given.
TEST(SurfaceQuilting, AnOverFineBaseIsSimplifiedFirst) {
  TriMesh base = test::plane_grid(4, 4, 330, 320);
  for (int v = 0; v < base.num_vertices(); ++v)
    base.V(v, 2) = 0.4 * std::sin(base.V(v, 0)) * std::cos(0.7 * base.V(v, 1));
  ASSERT_GT(base.num_faces(), 200'000);
  SurfaceQuiltingOptions o;
  o.scale = 0.1;
  // Guidance along x on the half x < 2, along y on the rest, per input face.
  o.field.resize(base.num_faces(), 3);
  for (int f = 0; f < base.num_faces(); ++f) {
    double x = 0;
    for (int k = 0; k < 3; ++k) x += base.V(base.F(f, k), 0) / 3;
    o.field.row(f) = x < 2 ? Vector3d(1, 0, 0).transpose() : Vector3d(0, 1, 0).transpose();
  }
  SurfaceQuiltingStats stats;
  const SurfaceJob job = prepare_surface_job(base, test::tiny_chainmail(), o, stats);
  const double H = bounding_box(test::tiny_chainmail().V).extent().minCoeff() * job.swatch_scale;
  std::printf("[ measure  ] %d faces -> proxy of %d faces, error %.2e (allowed %.2e)\n",
              base.num_faces(), stats.proxy_faces, stats.proxy_error, o.proxy_error * H);
  EXPECT_GT(stats.proxy_faces, 0);
  EXPECT_LT(stats.proxy_faces, base.num_faces() / 10);
  EXPECT_EQ(job.cleaned.num_faces(), stats.proxy_faces);
  EXPECT_LE(stats.proxy_error, o.proxy_error * H);
  // Every proxy vertex lies on the sheet.
  for (int v = 0; v < job.cleaned.num_vertices(); ++v) {
    const Vector3d p = job.cleaned.V.row(v).transpose();
    EXPECT_NEAR(p.z(), 0.4 * std::sin(p.x()) * std::cos(0.7 * p.y()), 1e-12);
  }
  // The guidance reached the refined faces from the input faces they came from: along x well
  // inside the first half, along y well inside the second (within the sheet's slope).
  ASSERT_EQ(job.field.rows(), job.base.num_faces());
  for (int f = 0; f < job.base.num_faces(); ++f) {
    double x = 0;
    for (int k = 0; k < 3; ++k) x += job.base.V(job.base.F(f, k), 0) / 3;
    if (x < 1.8) {
      EXPECT_GT(std::abs(job.field(f, 0)), 0.7) << "face " << f;
    } else if (x > 2.2) {
      EXPECT_GT(std::abs(job.field(f, 1)), 0.7) << "face " << f;
    }
  }
  o.proxy_min_faces = 0;
  SurfaceQuiltingStats kept;
  EXPECT_EQ(prepare_surface_job(base, test::tiny_chainmail(), o, kept).cleaned.num_faces(),
            base.num_faces());
  EXPECT_EQ(kept.proxy_faces, 0);
}

}  // namespace
}  // namespace mq
