// A saved quilt on its base moved (issue 25): prism coordinates locate and place points
// exactly; on the unmoved base the output is kept bit for bit; compact elements move rigidly
// with the surface, long ones follow it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/mesh/geometry_measures.h"
#include "core/shell/follow_base.h"
#include "core/shell/quilt_embedding.h"
#include "core/surface/global_quilting.h"
#include "tests/core/planar_checks.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(PrismCoordinates, PointsInTheShellAreLocatedExactly) {
  const TriMesh sphere = test::uv_sphere(1.0, 24, 12);
  const MatrixX3d N = vertex_normals(sphere.V, sphere.F);
  const double H = 0.1;
  std::mt19937_64 rng(3);
  MatrixX3d P(500, 3);
  for (int i = 0; i < P.rows(); ++i) {
    const Vector3d d(test::uniform(rng, -1, 1), test::uniform(rng, -1, 1),
                     test::uniform(rng, -1, 1));
    P.row(i) = (d.normalized() * (1.0 + test::uniform(rng, 0.0, H))).transpose();
  }
  int inexact = -1;
  const LocalCoordinates c = locate_in_prisms(sphere.V, sphere.F, N, H, P, &inexact);
  EXPECT_EQ(inexact, 0);
  for (int i = 0; i < P.rows(); ++i) {
    const Vector3d b = c.bary.row(i).transpose();
    EXPECT_LE((prism_point(sphere.V, sphere.F, N, c.face(i), b, c.height(i)) - P.row(i).transpose())
                  .norm(),
              1e-9 * H);
    EXPECT_NEAR(b.sum(), 1.0, 1e-12);
    EXPECT_GT(c.height(i), -0.5 * H);
    EXPECT_LT(c.height(i), 1.5 * H);
  }
}

// A quilt over a 2 x 1 sheet: 18 small closed boxes (compact) and one long bar along x.
SavedQuilt sheet_quilt() {
  SurfaceQuilt quilt;
  quilt.input_base = test::plane_grid(2.0, 1.0, 20, 10);
  quilt.shell_height = 0.05;
  for (int v = 0; v < quilt.input_base.num_vertices(); ++v) quilt.input_vertex.push_back(v);
  TriMesh output;
  const TriMesh box = test::unit_cube();
  auto add_box = [&](const Vector3d& lo, const Vector3d& size) {
    TriMesh b = box;
    b.V = (b.V.array().rowwise() * size.transpose().array()).matrix();
    b.V.rowwise() += lo.transpose();
    const auto offset = static_cast<int>(output.V.rows());
    output.V.conservativeResize(output.V.rows() + b.V.rows(), 3);
    output.V.bottomRows(b.V.rows()) = b.V;
    output.F.conservativeResize(output.F.rows() + b.F.rows(), 3);
    output.F.bottomRows(b.F.rows()) = b.F.array() + offset;
  };
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 2; ++j)
      add_box(Vector3d(0.1 + 0.2 * i, 0.2 + 0.4 * j, 0.01), Vector3d(0.06, 0.06, 0.03));
  add_box(Vector3d(0.1, 0.45, 0.01), Vector3d(1.8, 0.04, 0.03));
  SavedQuiltHeader header;
  header.base = fingerprint(quilt.input_base);
  int inexact = -1;
  SavedQuilt saved = make_saved_quilt(quilt, output, header, &inexact);
  EXPECT_EQ(inexact, 0);
  return saved;
}

TEST(FollowBase, TheUnmovedBaseKeepsTheOutputBitForBit) {
  const SavedQuilt saved = sheet_quilt();
  FollowBaseStats stats;
  const TriMesh out = follow_base(saved, saved.base.V, {}, &stats);
  EXPECT_EQ(out.V, saved.output.V);
  EXPECT_EQ(out.F, saved.output.F);
  EXPECT_EQ(stats.unmoved, 19);
}

TEST(FollowBase, CompactElementsMoveRigidlyAndLongOnesFollow) {
  const SavedQuilt saved = sheet_quilt();
  // The sheet rolled onto a cylinder of radius 1 (an isometry of the surface) and stretched
  // 10% along y: boxes must keep their shape, the bar must bend with the surface.
  MatrixX3d V = saved.base.V;
  for (int v = 0; v < V.rows(); ++v) {
    const double a = V(v, 0);
    V.row(v) << std::sin(a), 1.1 * V(v, 1), 1.0 - std::cos(a);
  }
  FollowBaseStats stats;
  const TriMesh out = follow_base(saved, V, {}, &stats);
  ASSERT_EQ(out.F, saved.output.F);
  EXPECT_EQ(stats.rigid, 18);
  EXPECT_EQ(stats.following, 1);
  EXPECT_EQ(stats.num_removed, 0);
  // Rigid: every edge keeps its length to rounding.
  const int box_faces = 12;
  for (int f = 0; f < 18 * box_faces; ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = out.F(f, k), b = out.F(f, (k + 1) % 3);
      EXPECT_NEAR((out.V.row(a) - out.V.row(b)).norm(),
                  (saved.output.V.row(a) - saved.output.V.row(b)).norm(), 1e-12);
    }
  // The boxes sit on the rolled surface: each vertex within the shell over it.
  for (int v = 0; v < 18 * 8; ++v) {
    const Vector3d p = out.V.row(v).transpose();
    const double r = std::hypot(p(0), 1.0 - p(2));  // distance from the cylinder's axis
    EXPECT_GT(1.0 - r, 0.0);
    EXPECT_LT(1.0 - r, 0.06);
  }
  // The bar bends along the cylinder: its far end turned by about 1.9 radians.
  EXPECT_GT(out.V.bottomRows(8).col(2).maxCoeff(), 1.0);
}

TEST(FollowBase, ElementsPressedTogetherFollowOrGoInEveryFrame) {
  const SavedQuilt saved = sheet_quilt();
  // Compressed to 70% along x: rigid boxes 0.2 apart of size 0.06 still fit (0.14 > 0.06),
  // compressed to 25% they would overlap: they follow the surface instead.
  for (const double squeeze : {0.7, 0.25}) {
    MatrixX3d V = saved.base.V;
    V.col(0) *= squeeze;
    FollowBaseStats stats;
    const TriMesh out = follow_base(saved, V, {}, &stats);
    EXPECT_EQ(stats.num_removed, 0);
    if (squeeze > 0.5) {
      EXPECT_EQ(stats.unbent, 0);
    } else {
      EXPECT_GT(stats.unbent, 0);
    }
    // Kept whole: the same faces whatever happens.
    FollowBaseOptions keep;
    keep.keep_elements = true;
    EXPECT_EQ(follow_base(saved, V, keep, &stats).F, saved.output.F);
    EXPECT_EQ(stats.num_removed, 0);
    // Asked to remove element 3 (as a sequence does), it is gone and nothing else.
    FollowBaseOptions options;
    options.remove.assign(19, 0);
    options.remove[3] = 1;
    const TriMesh fewer = follow_base(saved, V, options, &stats);
    EXPECT_EQ(fewer.num_faces(), out.num_faces() - 12);
    EXPECT_EQ(stats.num_removed, 1);
  }
}

// A base quilted over a simplified proxy (issue 25: --save-quilt refused such bases): the quilt
// is saved over the base as given, follows it, and on the unmoved base gives the output bit for
// bit. A sphere of 5,120 faces, simplified when over 1,000 (to about half, as 20,480 faces at
// Scale 0.08 were: the same case at a quarter of the cost, 54 s under the sanitizers before).
TEST(FollowBase, AQuiltMadeOverAProxyFollowsTheBaseGiven) {
  TriMesh base = test::icosphere(4);
  base.V *= 3.0;
  SurfaceQuiltingOptions o;
  o.proxy_min_faces = 1000;
  o.scale = 0.25;
  TranslationCostCpu cost;
  SurfaceQuiltingStats stats;
  const SurfaceQuilt quilt = quilt_surface_global(base, test::tiny_chainmail(), o, cost, &stats);
  ASSERT_GT(stats.proxy_faces, 0);
  ASSERT_TRUE(quilt.input_vertex.empty());
  EXPECT_EQ(quilt.welded_base.num_faces(), base.num_faces());
  QuiltEmbeddingOptions e;
  TetStretchCpu stretch;
  const TriMesh output = embed_quilt(quilt, e, stretch);
  ASSERT_GT(output.num_faces(), 0);
  SavedQuiltHeader header;
  header.base = fingerprint(base);
  int inexact = -1;
  const SavedQuilt saved = make_saved_quilt(quilt, output, header, &inexact);
  std::printf("[ measure  ] proxy of %d faces for %d: %d of %d output vertices placed inexactly\n",
              stats.proxy_faces, base.num_faces(), inexact, output.num_vertices());
  EXPECT_LE(inexact, output.num_vertices() / 100);
  EXPECT_EQ(saved.base.num_faces(), base.num_faces());
  const MatrixX3d rest = welded_positions(saved, base);
  const TriMesh same = follow_base(saved, rest, {}, nullptr);
  EXPECT_EQ(same.V, output.V);
  // Moved as a whole, the output moves with it.
  TriMesh moved = base;
  moved.V.rowwise() += Eigen::RowVector3d(0.5, -1.0, 2.0);
  const TriMesh out = follow_base(saved, welded_positions(saved, moved), {}, nullptr);
  ASSERT_EQ(out.V.rows(), output.V.rows());
  EXPECT_LT((out.V.rowwise() - Eigen::RowVector3d(0.5, -1.0, 2.0) - output.V).cwiseAbs().maxCoeff(),
            1e-9);
}

}  // namespace
}  // namespace mq
