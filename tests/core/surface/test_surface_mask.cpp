// Masks (issue 25 item 3): the file's two forms and its errors, and a masked quilt (a disc on a
// generated square, Spot's head) keeps whole elements, reaches at most one element past the
// mask and covers the mask as the unmasked run covers it.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/shell/quilt_embedding.h"
#include "core/shell/surface_coverage.h"
#include "core/surface/global_quilting.h"
#include "core/surface/surface_mask.h"
#include "core/surface/vertex_map_io.h"
#include "tests/core/planar_checks.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TEST(SurfaceMask, ParsesVertexWeightsAndFaceLists) {
  const TriMesh base = test::plane_grid(1, 1, 1, 1);  // 4 vertices, 2 faces
  const SurfaceMask w = parse_surface_mask("# weights\n0\n0.25\n\n1\n0.5\n", "m", base);
  ASSERT_EQ(w.vertex_weight.size(), 4);
  EXPECT_TRUE(w.face.empty());
  for (int f = 0; f < 2; ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(w.contains(base, f, Vector3d::Unit(k)), w.vertex_weight(base.F(f, k)) >= 0.5);
  // Interpolated across a face: the centroid's weight is the mean of the corners'.
  for (int f = 0; f < 2; ++f) {
    double mean = 0;
    for (int k = 0; k < 3; ++k) mean += w.vertex_weight(base.F(f, k)) / 3;
    EXPECT_EQ(w.contains(base, f, Vector3d::Constant(1.0 / 3)), mean >= 0.5);
  }
  const SurfaceMask f = parse_surface_mask("faces\r\n1\r\n1\n", "m", base);
  EXPECT_EQ(f.face, (std::vector<char>{0, 1}));
  EXPECT_EQ(f.vertex_weight.size(), 0);
  EXPECT_FALSE(f.contains(base, 0, Vector3d(1, 0, 0)));
  EXPECT_TRUE(f.contains(base, 1, Vector3d(1, 0, 0)));
}

TEST(SurfaceMask, RefusesBadFilesInOneLine) {
  const TriMesh base = test::plane_grid(1, 1, 1, 1);
  for (const char* text :
       {"", "# nothing\n", "1\n1\n1\n", "1\n1\n1\n1\n1\n", "0\nnan\n1\n1\n", "0\n1.5\n1\n1\n",
        "0\n-0.1\n1\n1\n", "0 1\n1\n1\n1\n", "0\n0\n0.49\n0\n", "faces\n", "faces\n2\n",
        "faces\n-1\n", "faces\nx\n", "faces\n0.5\n", "faces\n99999999999999999999\n"}) {
    SCOPED_TRACE(text);
    try {
      parse_surface_mask(text, "mask.txt", base);
      ADD_FAILURE() << "accepted";
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_EQ(what.rfind("mask.txt", 0), 0u) << what;
    }
  }
  EXPECT_THROW(read_surface_mask("/nonexistent/mask.txt", base), InvalidInput);
}

// One quilt, embedded whole and masked (by normal displacement: the masking is the same for
// the shell map, which the CLI test runs): the checks of issue 25 item 3.
void expect_masked(const TriMesh& base, const SurfaceMask& mask, double ring, const char* what,
                   const MatrixX3d& field = MatrixX3d()) {
  SCOPED_TRACE(what);
  const TriMesh swatch = test::tiny_chainmail();
  SurfaceQuiltingOptions o;
  o.element_size = ring / 2.24 * bounding_box(swatch.V).extent().head<2>().maxCoeff();
  o.field = field;
  TranslationCostCpu cost;
  const SurfaceQuilt quilt = quilt_surface_global(base, swatch, o, cost);
  const std::vector<char> faces = mask_quilt_faces(mask, base, quilt);
  QuiltEmbeddingOptions e;
  e.shell_map = false;
  TetStretchCpu stretch;
  const TriMesh whole = embed_quilt(quilt, e, stretch);
  SurfaceQuilt masked = quilt;
  const int dropped = drop_unmasked_elements(masked, faces);
  e.coverage_faces = faces;
  QuiltEmbeddingStats stats;
  const TriMesh out = embed_quilt(masked, e, stretch, &stats);
  const double h = quilt.shell_height;
  const double whole_inside = surface_coverage(quilt.base, whole, 1.5 * h, 0.01 * h, faces);
  // Distance to the mask: to the refined faces in it (the surface's distance, approximately).
  std::vector<int> inside;
  for (int f = 0; f < quilt.base.num_faces(); ++f)
    if (faces[static_cast<size_t>(f)]) inside.push_back(f);
  const TriMesh region = extract_faces(quilt.base, inside);
  const Eigen::VectorXd d = point_mesh_distance(out.V, region.V, region.F);
  std::printf(
      "[ measure  ] %s: %d of %zu elements kept, coverage inside %.2f%% (unmasked %.2f%%), "
      "farthest vertex %.3f elements outside\n",
      what, static_cast<int>(masked.elements.size()), quilt.elements.size(), 100 * stats.coverage,
      100 * whole_inside, d.maxCoeff() / ring);
  EXPECT_GT(dropped, 0);
  EXPECT_GT(masked.elements.size(), 10u);
  EXPECT_GE(stats.coverage, 0.95 * whole_inside);
  EXPECT_GT(stats.coverage, 0.5);
  EXPECT_LE(d.maxCoeff(), ring);
  // Whole elements at the border: every ring as in the swatch, closed.
  const TriMesh one = test::components(swatch).front();
  for (const TriMesh& c : test::components(out)) {
    EXPECT_EQ(c.num_vertices(), one.num_vertices());
    EXPECT_EQ(c.num_faces(), one.num_faces());
    EXPECT_TRUE(topology_report(c).closed());
  }
}

TEST(SurfaceMask, DiscOnASquareKeepsWholeElements) {
  const TriMesh base = test::plane_grid(10, 10, 20, 20);
  SurfaceMask mask;
  mask.face.assign(static_cast<size_t>(base.num_faces()), 0);
  for (int f = 0; f < base.num_faces(); ++f) {
    const Vector3d c =
        (base.V.row(base.F(f, 0)) + base.V.row(base.F(f, 1)) + base.V.row(base.F(f, 2)))
            .transpose() /
        3;
    mask.face[static_cast<size_t>(f)] = (c - Vector3d(5, 5, 0)).norm() < 3;
  }
  expect_masked(base, mask, 0.8, "disc on a square",
                MatrixX3d(Vector3d(1, 0, 0).transpose().replicate(base.num_faces(), 1)));
}

TEST(SurfaceMask, SpotsHeadByVertexWeights) {
  const TriMesh base = read_mesh(test::shared_data("base/spot_6k.obj"));
  // The head: vertices within 0.4 of a point between the horns and the snout.
  SurfaceMask mask;
  mask.vertex_weight.resize(base.num_vertices());
  for (int v = 0; v < base.num_vertices(); ++v)
    mask.vertex_weight(v) =
        (base.V.row(v).transpose() - Vector3d(0, 0.5, -0.4)).norm() < 0.4 ? 1.0 : 0.0;
  expect_masked(base, mask, 0.1, "Spot's head");
}

}  // namespace
}  // namespace mq
