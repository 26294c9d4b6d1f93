// Element correspondences (paper section 2.5): vertex-face pairs, their pruning and the element
// relations, on a swatch of two separate tori placed over an output made of copies of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <set>
#include <utility>

#include "core/mesh/mesh_topology.h"
#include "core/planar/element_correspondence.h"
#include "core/planar/synthesis_grid.h"
#include "tests/test_support.h"

namespace mq {
namespace {

struct TwoTori {
  PreparedSwatch swatch;
  std::unique_ptr<SwatchFaceTree> faces;
  SynthesisGrid grid{Vector2d(0, 0), 1.0, 20, 20};
  Vector3d t{5, 6, 0};
  TwoTori() {
    TriMesh m = test::torus(1.0, 0.3, 24, 12);
    TriMesh b = test::torus(1.0, 0.3, 24, 12);
    b.V.col(0).array() += 4.0;
    append_mesh(m, b);
    swatch = prepare_swatch(m);
    faces = std::make_unique<SwatchFaceTree>(swatch.mesh.V, swatch.mesh.F);
    for (int i = 0; i < grid.num_cells(); ++i) grid.set_processed(grid.cell(i));
  }
  // The swatch elements placed at t: the output the new patch matches exactly.
  std::vector<Element> placed() const {
    std::vector<Element> out = swatch.elements;
    for (Element& e : out) e.translate(t);
    return out;
  }
  Correspondences find(const std::vector<Element>& output, const CorrespondenceOptions& o = {}) {
    const OverlapRegion region(t.head<2>(), t.head<2>() + swatch.size.head<2>(),
                               grid.processed_snapshot());
    std::vector<int> candidates(output.size());
    for (size_t i = 0; i < output.size(); ++i) candidates[i] = static_cast<int>(i);
    return find_correspondences(output, candidates, region, swatch, *faces, t, o);
  }
};

TEST(ElementCorrespondence, IdenticalPlacementPairsEveryVertexWithItsOwnElement) {
  TwoTori fx;
  ASSERT_EQ(fx.swatch.elements.size(), 2u);
  const std::vector<Element> output = fx.placed();
  const Correspondences c = fx.find(output);
  const std::vector<std::pair<int, int>> expected{{0, 0}, {1, 1}};
  EXPECT_EQ(c.relations, expected);
  EXPECT_EQ(c.pairs.size(), static_cast<size_t>(output[0].V.rows() + output[1].V.rows()));
  for (const VertexFacePair& p : c.pairs) {
    EXPECT_EQ(p.out_element, p.in_element);
    EXPECT_LT(p.distance, 1e-9);
    EXPECT_LT((p.closest - Vector3d(output[p.out_element].V.row(p.out_vertex).transpose())).norm(),
              1e-9);
    EXPECT_NEAR(p.barycentric.sum(), 1.0, 1e-9);
  }
}

TEST(ElementCorrespondence, VerticesWithoutANormalAreSkipped) {
  // A vertex whose faces all collapsed has a zero (or NaN) normal: it is left unpaired instead of
  // failing the whole patch (seen on a weave over the bunny).
  TwoTori fx;
  std::vector<Element> output = fx.placed();
  output[0].N.row(0).setZero();
  output[0].N.row(1).setConstant(std::numeric_limits<double>::quiet_NaN());
  Correspondences c;
  ASSERT_NO_THROW(c = fx.find(output));
  EXPECT_EQ(c.pairs.size(), static_cast<size_t>(output[0].V.rows() + output[1].V.rows() - 2));
  for (const VertexFacePair& p : c.pairs) EXPECT_FALSE(p.out_element == 0 && p.out_vertex < 2);
}

TEST(ElementCorrespondence, OppositeNormalsArePruned) {
  TwoTori fx;
  std::vector<Element> output = fx.placed();
  // Same place, inside out: every vertex normal opposes the face it lies on.
  output[0].F.col(1).swap(output[0].F.col(2));
  output[0].update();
  const Correspondences c = fx.find(output);
  const std::vector<std::pair<int, int>> expected{{1, 1}};
  EXPECT_EQ(c.relations, expected);
  for (const VertexFacePair& p : c.pairs) EXPECT_EQ(p.out_element, 1);
  // With the normal test disabled the flipped torus pairs again.
  CorrespondenceOptions lax;
  lax.min_normal_dot = -2;
  EXPECT_EQ(fx.find(output, lax).relations.size(), 2u);
}

TEST(ElementCorrespondence, FarPairsArePruned) {
  TwoTori fx;
  const double limit = CorrespondenceOptions{}.prune_distance * fx.swatch.mean_edge_length;
  std::vector<Element> output = fx.placed();
  // Lifted clear of the swatch torus by more than the pruning distance: no pair survives.
  output[0].translate(Vector3d(0, 0, 0.6 + 2 * limit));
  // Lifted by a fraction of it: every vertex still pairs, at about that distance.
  output[1].translate(Vector3d(0, 0, 0.25 * limit));
  const Correspondences c = fx.find(output);
  const std::vector<std::pair<int, int>> expected{{1, 1}};
  EXPECT_EQ(c.relations, expected);
  EXPECT_EQ(c.pairs.size(), static_cast<size_t>(output[1].V.rows()));
  for (const VertexFacePair& p : c.pairs) EXPECT_LE(p.distance, 0.25 * limit + 1e-9);
}

TEST(ElementCorrespondence, OnlyVerticesInTheOverlappingRegionArePaired) {
  TwoTori fx;
  // Only the cells left of x = 7 are processed: the first torus (x in [5, 7.6]) partly.
  SynthesisGrid g(Vector2d(0, 0), 1.0, 20, 20);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 7; ++x) g.set_processed({x, y});
  fx.grid = g;
  const std::vector<Element> output = fx.placed();
  const Correspondences c = fx.find(output);
  const std::vector<std::pair<int, int>> expected{{0, 0}};
  EXPECT_EQ(c.relations, expected);
  ASSERT_FALSE(c.pairs.empty());
  EXPECT_LT(c.pairs.size(), static_cast<size_t>(output[0].V.rows()));
  for (const VertexFacePair& p : c.pairs) EXPECT_LT(output[0].V(p.out_vertex, 0), 7.0);
}

TEST(ElementCorrespondence, ProjectionsOverlap) {
  TwoTori fx;
  const Element& a = fx.swatch.elements[0];
  const Element& b = fx.swatch.elements[1];  // 4 units away, footprints 2.6 wide
  const double res = fx.swatch.mean_edge_length;
  EXPECT_FALSE(projections_overlap(a, b, res));
  EXPECT_EQ(footprint_overlap(a, b, res), 0.0);
  EXPECT_TRUE(projections_overlap(a, a, res));
  EXPECT_DOUBLE_EQ(footprint_overlap(a, a, res), 1.0);
  // Half a diameter apart: a partial overlap, the same both ways.
  Element c = a;
  c.translate(Vector3d(1.3, 0, 0));
  const double o = footprint_overlap(a, c, res);
  EXPECT_TRUE(projections_overlap(a, c, res));
  EXPECT_GT(o, 0.1);
  EXPECT_LT(o, 0.9);
  EXPECT_DOUBLE_EQ(o, footprint_overlap(c, a, res));
  // Bounding boxes that overlap while the triangles do not: the ring's hole.
  Element small = a;
  small.V = (small.V.rowwise() - small.V.colwise().mean()) * 0.2;
  small.V.rowwise() += a.V.colwise().mean();
  small.update();
  EXPECT_FALSE(projections_overlap(a, small, 0.05));
}

}  // namespace
}  // namespace mq
