// Planar quilting at realistic sizes: one run per generated swatch kind at its default
// resolution, and the large real swatches. Labelled "slow" (ctest -LE slow skips them).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"
#include "core/planar/planar_quilting.h"
#include "tests/core/planar_checks.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TriMesh quilt_plane_sized(const TriMesh& swatch, double L, double W,
                          PlanarQuiltingStats* stats = nullptr) {
  PlanarQuiltingOptions o;
  o.length = L;
  o.width = W;
  TranslationCostCpu cpu;
  return quilt_plane(swatch, o, cpu, stats);
}

TEST(PlanarQuiltingSlow, ChainMailDefaultSwatch20x20) {
  const TriMesh swatch = chainmail_4in1();
  PlanarQuiltingStats stats;
  const TriMesh out = quilt_plane_sized(swatch, 20, 20, &stats);
  test::expect_valid_quilt(swatch, out, 20, 20);
  EXPECT_GT(stats.elements, 36 * 4);
}

TEST(PlanarQuiltingSlow, AppleLayerDefaultSwatch) {
  const TriMesh swatch = apple_layer();
  const BoundingBox b = bounding_box(swatch.V, swatch.F);
  const double L = 2.5 * b.extent().x(), W = 2.5 * b.extent().y();
  const TriMesh out = quilt_plane_sized(swatch, L, W);
  test::expect_valid_quilt(swatch, out, L, W);
}

TEST(PlanarQuiltingSlow, WeaveDefaultSwatch) {
  const TriMesh swatch = plain_weave();
  const BoundingBox b = bounding_box(swatch.V, swatch.F);
  const double L = 2.5 * b.extent().x(), W = 2.5 * b.extent().y();
  PlanarQuiltingStats stats;
  const TriMesh out = quilt_plane_sized(swatch, L, W, &stats);
  test::QuiltExpectations expect;
  expect.check_diameters = false;
  test::expect_valid_quilt(swatch, out, L, W, expect);
  EXPECT_GT(stats.counts.stitched, 0);
  double mean_in = 0, mean_out = 0;
  const auto in = test::footprint_diameters(test::components(swatch));
  const auto got = test::footprint_diameters(test::components(out));
  for (const double d : in) mean_in += d / in.size();
  for (const double d : got) mean_out += d / got.size();
  EXPECT_GT(mean_out, 1.5 * mean_in);
}

TEST(PlanarQuiltingSlow, IvyDefaultSwatch) {
  const TriMesh swatch = ivy_section();
  const BoundingBox b = bounding_box(swatch.V, swatch.F);
  const double L = 2.5 * b.extent().x(), W = 2.5 * b.extent().y();
  const TriMesh out = quilt_plane_sized(swatch, L, W);
  test::QuiltExpectations expect;
  expect.check_diameters = false;
  expect.check_coverage = false;
  test::expect_valid_quilt(swatch, out, L, W, expect);
}

// The large real swatches: each quilts (closed elements stay closed, none intersect) or is
// refused with a one-line InvalidInput.
void expect_quilts_or_refuses(const std::string& file, double scale) {
  SCOPED_TRACE(file);
  const TriMesh swatch = read_mesh(test::shared_data("swatch/" + file));
  const bool closed_input = topology_report(swatch).closed();
  Vector3d e = bounding_box(swatch.V, swatch.F).extent();
  std::sort(e.data(), e.data() + 3);
  try {
    const TriMesh out = quilt_plane_sized(swatch, scale * e(2), scale * e(1));
    ASSERT_GT(out.num_faces(), 0);
    if (closed_input) {
      for (const TriMesh& part : test::components(out)) EXPECT_TRUE(topology_report(part).closed());
    }
    EXPECT_TRUE(intersecting_face_pairs(out.V, out.F).empty());
  } catch (const InvalidInput& err) {
    EXPECT_EQ(std::string(err.what()).find('\n'), std::string::npos) << err.what();
  }
}

TEST(PlanarQuiltingSlow, ChainLinkHalf) { expect_quilts_or_refuses("chainlink_half_12k.obj", 2.0); }

TEST(PlanarQuiltingSlow, ChainMail3dBlock) {
  expect_quilts_or_refuses("chainmail3d_48rings_49k.obj", 1.5);
}

}  // namespace
}  // namespace mq
