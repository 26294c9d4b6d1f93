#include <gtest/gtest.h>

#include "core/closest_point_query.h"
#include "core/errors.h"
#include "core/geometry_measures.h"
#include "core/mesh_io.h"
#include "core/mesh_topology.h"
#include "core/surface_quilting.h"
#include "core/swatch_generators.h"
#include "core/translation_cost.h"
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

}  // namespace
}  // namespace mq
