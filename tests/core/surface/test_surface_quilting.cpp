#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "core/planar/translation_cost.h"
#include "core/surface/surface_quilting.h"
#include "tests/core/planar_checks.h"
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
