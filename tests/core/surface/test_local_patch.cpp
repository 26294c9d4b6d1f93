#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "core/common/errors.h"
#include "core/mesh/boundary_loops.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/surface/local_patch.h"
#include "core/surface/lscm.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Checks every documented guarantee of a grown patch; returns its area.
void expect_valid_patch(const TriMesh& base, const LocalPatch& p, int seed,
                        const LocalPatchOptions& o, const std::string& what) {
  SCOPED_TRACE(what + " seed " + std::to_string(seed));
  ASSERT_FALSE(p.faces.empty());
  EXPECT_EQ(p.faces[0], seed);
  ASSERT_EQ(p.mesh.F.rows(), static_cast<int>(p.faces.size()));
  ASSERT_EQ(p.mesh.V.rows(), static_cast<int>(p.vertex_map.size()));
  ASSERT_EQ(p.uv.rows(), p.mesh.V.rows());
  EXPECT_EQ(std::set<int>(p.faces.begin(), p.faces.end()).size(), p.faces.size());
  // The patch's faces are the base faces, renumbered.
  for (size_t i = 0; i < p.faces.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(p.vertex_map[p.mesh.F(static_cast<int>(i), k)], base.F(p.faces[i], k));
  for (size_t i = 0; i < p.vertex_map.size(); ++i)
    ASSERT_EQ(p.mesh.V.row(static_cast<int>(i)), base.V.row(p.vertex_map[i]));
  // A topological disk.
  const int nv = p.mesh.num_vertices();
  const EdgeTopology topo = edge_topology(p.mesh.F, nv);
  EXPECT_EQ(nv - topo.num_edges() + p.mesh.num_faces(), 1);
  EXPECT_EQ(boundary_loops(p.mesh.F, nv).size(), 1u);
  EXPECT_TRUE(topology_report(p.mesh).manifold());
  EXPECT_EQ(topology_report(p.mesh).num_components, 1);
  // Area bound: at most one face beyond max_area.
  const Eigen::VectorXd areas = face_areas(p.mesh.V, p.mesh.F);
  EXPECT_NEAR(p.area, areas.sum(), 1e-9 * areas.sum());
  if (o.max_area > 0) {
    EXPECT_LT(p.area, o.max_area + areas.maxCoeff());
  }
  // Flattening.
  EXPECT_EQ(count_flipped(p.mesh.F, p.uv), 0);
  const Eigen::VectorXd d = face_area_distortion(p.mesh.V, p.mesh.F, p.uv);
  EXPECT_DOUBLE_EQ(d.maxCoeff(), p.max_distortion);
  if (p.faces.size() > 1) {
    EXPECT_LE(p.distortion, o.max_distortion);
    // The bounded figure is the 95th percentile of the face distortions.
    std::vector<double> sorted(d.data(), d.data() + d.size());
    std::sort(sorted.begin(), sorted.end());
    EXPECT_DOUBLE_EQ(p.distortion, sorted[std::min(sorted.size() - 1, sorted.size() * 95 / 100)]);
    EXPECT_LE(p.distortion, p.max_distortion);
  }
}

struct BaseCase {
  const char* file;
  double patch_faces;  // target patch size in mean face areas
};

class LocalPatchOnRealMeshes : public ::testing::TestWithParam<BaseCase> {};

TEST_P(LocalPatchOnRealMeshes, PatchesAreFlattenedDisks) {
  const TriMesh base = read_mesh(test::shared_data(std::string("base/") + GetParam().file));
  LocalPatchBuilder builder(base);
  const double mean_area = surface_area(base.V, base.F) / base.num_faces();
  LocalPatchOptions o;
  o.max_area = GetParam().patch_faces * mean_area;
  const int seeds = 40;
  size_t total = 0;
  for (int i = 0; i < seeds; ++i) {
    const int seed = static_cast<int>((static_cast<long long>(i) * 7919 + 13) % base.num_faces());
    if (face_areas(base.V, base.F)(seed) <= 0) continue;
    const LocalPatch p = builder.grow(seed, o);
    expect_valid_patch(base, p, seed, o, GetParam().file);
    total += p.faces.size();
  }
  // Most patches reach a substantial fraction of the requested size.
  EXPECT_GT(static_cast<double>(total) / seeds, 0.25 * GetParam().patch_faces);
  // Large, unlimited-distortion patches on the same mesh, and depth-limited ones.
  LocalPatchOptions big;
  big.max_area = 20 * o.max_area;
  for (int i = 0; i < 4; ++i) {
    const int seed = (i * 104729 + 7) % base.num_faces();
    if (face_areas(base.V, base.F)(seed) <= 0) continue;
    expect_valid_patch(base, builder.grow(seed, big), seed, big, "big");
    LocalPatchOptions shallow;
    shallow.max_radius = 3 * std::sqrt(mean_area);
    expect_valid_patch(base, builder.grow(seed, shallow), seed, shallow, "shallow");
  }
}

INSTANTIATE_TEST_SUITE_P(Bases, LocalPatchOnRealMeshes,
                         ::testing::Values(BaseCase{"bunny_igl_7k.off", 300},
                                           BaseCase{"cup_mug_11k.off", 500},
                                           BaseCase{"knight_decimated_1k.off", 80},
                                           BaseCase{"lilium_7k.obj", 300},
                                           BaseCase{"teapot_6k.obj", 300}),
                         [](const auto& info) {
                           std::string n = info.param.file;
                           return n.substr(0, n.find('_'));
                         });

TEST(LocalPatch, RadiusLimits) {
  const TriMesh grid = test::plane_grid(1, 1, 10, 10);
  LocalPatchBuilder builder(grid);
  LocalPatchOptions o;
  o.max_radius = 1e-9;
  EXPECT_EQ(builder.grow(57, o).faces, std::vector<int>{57});
  // Centroids of edge neighbours lie 0.047 away (the diagonal neighbour) or 0.075 (the others);
  // no other face's centroid is nearer than 0.1.
  o.max_radius = 0.08;
  const LocalPatch p = builder.grow(57, o);
  EXPECT_EQ(p.faces.size(), 4u);  // the seed and its three edge neighbours
  const MatrixX3i TT = face_adjacency(edge_topology(grid.F, grid.num_vertices()));
  for (size_t i = 1; i < p.faces.size(); ++i) EXPECT_TRUE((TT.row(57).array() == p.faces[i]).any());
  EXPECT_NEAR(p.max_distortion, 1.0, 1e-9);
  // Every face of a larger radius patch lies within it along the surface (here: in the plane).
  o.max_radius = 0.3;
  const LocalPatch q = builder.grow(57, o);
  const Eigen::RowVector3d c0 =
      (grid.V.row(grid.F(57, 0)) + grid.V.row(grid.F(57, 1)) + grid.V.row(grid.F(57, 2))) / 3.0;
  for (const int f : q.faces) {
    const Eigen::RowVector3d c =
        (grid.V.row(grid.F(f, 0)) + grid.V.row(grid.F(f, 1)) + grid.V.row(grid.F(f, 2))) / 3.0;
    EXPECT_LE((c - c0).norm(), 0.3 + 1e-12);
  }
  EXPECT_GT(q.faces.size(), 20u);
}

// Patches follow distance, not adjacency steps: on a grid of thin triangles (cells ten times
// longer than wide) an area-limited patch is still round, not a strip along the long side.
TEST(LocalPatch, PatchesAreRoundOnThinTriangles) {
  const TriMesh strip = test::plane_grid(4, 4, 20, 200);  // cells 0.2 x 0.02
  LocalPatchBuilder builder(strip);
  LocalPatchOptions o;
  o.max_area = 3.14159 * 0.8 * 0.8;
  const int seed = 2 * (100 * 20 + 10);  // a face at the centre
  const LocalPatch p = builder.grow(seed, o);
  const Eigen::Vector2d extent =
      (p.mesh.V.leftCols<2>().colwise().maxCoeff() - p.mesh.V.leftCols<2>().colwise().minCoeff())
          .transpose();
  EXPECT_LT(extent.maxCoeff() / extent.minCoeff(), 1.6) << extent.transpose();
}

TEST(LocalPatch, UnlimitedGrowthCoversADiskAndStopsShortOfClosing) {
  const TriMesh grid = test::plane_grid(2, 1, 8, 5);
  LocalPatchBuilder grid_builder(grid);
  const LocalPatch all = grid_builder.grow(17);
  EXPECT_EQ(all.faces.size(), static_cast<size_t>(grid.num_faces()));
  EXPECT_EQ(all.shrink_steps, 0);
  // On a closed cube the last face would close the surface; flattening a cube with one face
  // missing is very distorted, so the patch shrinks.
  const TriMesh cube = test::unit_cube();
  LocalPatchBuilder cube_builder(cube);
  LocalPatchOptions o;
  o.max_distortion = 1e9;
  EXPECT_EQ(cube_builder.grow(3, o).faces.size(), 11u);
  const LocalPatch strict = cube_builder.grow(3);
  expect_valid_patch(cube, strict, 3, LocalPatchOptions{}, "cube");
}

TEST(LocalPatch, ShrinksUntilTheDistortionBoundHolds) {
  const TriMesh torus = test::torus(2, 0.7, 60, 30);
  LocalPatchBuilder builder(torus);
  LocalPatchOptions o;
  o.max_distortion = 1.3;
  const LocalPatch p = builder.grow(100, o);
  EXPECT_GT(p.shrink_steps, 0);
  expect_valid_patch(torus, p, 100, o, "torus");
  // The shrunk patch is a prefix of the unshrunk growth order.
  LocalPatchOptions loose;
  loose.max_distortion = 1e9;
  const LocalPatch q = builder.grow(100, loose);
  ASSERT_LT(p.faces.size(), q.faces.size());
  EXPECT_TRUE(std::equal(p.faces.begin(), p.faces.end(), q.faces.begin()));
}

TEST(LocalPatch, BuilderReuseMatchesFreshBuildsAndOneOffForm) {
  const TriMesh base = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  const EdgeTopology topo = edge_topology(base.F, base.num_vertices());
  const MatrixX3i TT = face_adjacency(topo);
  LocalPatchBuilder builder(base, topo, TT);
  LocalPatchOptions o;
  o.max_area = 0.05 * surface_area(base.V, base.F);
  for (int seed : {0, 500, 3, 500, 999}) {
    const LocalPatch a = builder.grow(seed, o);
    const LocalPatch b = grow_local_patch(base, topo, TT, seed, o);
    EXPECT_EQ(a.faces, b.faces);
    EXPECT_EQ(a.uv, b.uv);
  }
}

TEST(LocalPatch, RejectsBadSeedsAndOptions) {
  const TriMesh grid = test::plane_grid(1, 1, 3, 3);
  LocalPatchBuilder builder(grid);
  EXPECT_THROW(builder.grow(-1), InvalidInput);
  EXPECT_THROW(builder.grow(grid.num_faces()), InvalidInput);
  LocalPatchOptions o;
  o.max_area = -1;
  EXPECT_THROW(builder.grow(0, o), InvalidInput);
  o = {};
  o.max_distortion = 0.5;
  EXPECT_THROW(builder.grow(0, o), InvalidInput);
  o = {};
  o.max_radius = -1;
  EXPECT_THROW(builder.grow(0, o), InvalidInput);
  TriMesh degenerate = grid;
  degenerate.F(4, 1) = degenerate.F(4, 0);
  LocalPatchBuilder degenerate_builder(degenerate);
  EXPECT_THROW(degenerate_builder.grow(4), InvalidInput);
  // The degenerate face is never taken into a patch.
  const LocalPatch p = degenerate_builder.grow(0);
  EXPECT_EQ(std::count(p.faces.begin(), p.faces.end(), 4), 0);
}

}  // namespace
}  // namespace mq
