#include <gtest/gtest.h>

#include <cstdio>

#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"
#include "core/shell/texture_atlas.h"
#include "core/surface/lscm.h"
#include "tests/test_support.h"

namespace mq {
namespace {

void expect_valid_atlas(const TriMesh& m, const TextureAtlas& a, const std::string& name) {
  ASSERT_EQ(a.FUV.rows(), m.F.rows());
  ASSERT_EQ(static_cast<Eigen::Index>(a.face_chart.size()), m.F.rows());
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    ASSERT_GE(a.face_chart[f], 0);
    ASSERT_LT(a.face_chart[f], a.num_charts);
    for (int k = 0; k < 3; ++k) {
      // Every corner's UV row belongs to the corner's vertex, and is shared only within a chart.
      ASSERT_EQ(a.uv_vertex[a.FUV(f, k)], m.F(f, k));
    }
  }
  std::vector<int> uv_chart(a.UV.rows(), -1);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int& c = uv_chart[a.FUV(f, k)];
      if (c == -1) c = a.face_chart[f];
      ASSERT_EQ(c, a.face_chart[f]);
    }
  EXPECT_EQ(count_flipped(a.FUV, a.UV), 0) << name;
  std::vector<std::pair<int, int>> pairs;
  EXPECT_EQ(count_uv_overlaps(a, &pairs), 0) << name;
  for (std::size_t i = 0; i < std::min<std::size_t>(pairs.size(), 3); ++i)
    ADD_FAILURE() << "faces " << pairs[i].first << " (chart " << a.face_chart[pairs[i].first]
                  << ") and " << pairs[i].second << " (chart " << a.face_chart[pairs[i].second]
                  << ") overlap in UV";
  const double s = atlas_stretch(m.V, m.F, a);
  std::printf("[ atlas    ] %s: %d faces, %d charts, stretch %.4f\n", name.c_str(),
              static_cast<int>(m.F.rows()), a.num_charts, s);
  EXPECT_GE(s, 1.0 - 1e-12);
  EXPECT_LT(s, 1.5) << name;
}

TEST(TextureAtlas, RealMeshes) {
  for (const char* name :
       {"base/bunny_igl_7k.off", "base/cup_mug_11k.off", "base/knight_decimated_1k.off",
        "base/lilium_7k.obj", "base/teapot_6k.obj"}) {
    const TriMesh m = read_mesh(test::shared_data(name));
    expect_valid_atlas(m, texture_atlas(m.V, m.F), name);
  }
}

TEST(TextureAtlas, PlaneIsOneIsometricChart) {
  const TriMesh m = test::plane_grid(2.0, 1.0, 8, 4);
  const TextureAtlas a = texture_atlas(m.V, m.F);
  EXPECT_EQ(a.num_charts, 1);
  EXPECT_NEAR(atlas_stretch(m.V, m.F, a), 1.0, 1e-9);
  expect_valid_atlas(m, a, "plane");
}

TEST(TextureAtlas, ClosedCubeNeedsSeveralCharts) {
  const TriMesh m = test::unit_cube();
  const TextureAtlas a = texture_atlas(m.V, m.F);
  EXPECT_GE(a.num_charts, 2);                          // a closed surface is never one disk
  EXPECT_NEAR(atlas_stretch(m.V, m.F, a), 1.0, 1e-9);  // flat charts flatten isometrically
  expect_valid_atlas(m, a, "cube");
}

TEST(TextureAtlas, DeterministicAndStrictSmallBudget) {
  const TriMesh m = read_mesh(test::shared_data("base/knight_decimated_1k.off"));
  TextureAtlasOptions opt;
  opt.max_chart_faces = 10;
  const TextureAtlas a = texture_atlas(m.V, m.F, opt), b = texture_atlas(m.V, m.F, opt);
  EXPECT_EQ(a.UV, b.UV);
  EXPECT_EQ(a.FUV, b.FUV);
  EXPECT_GE(a.num_charts, m.F.rows() / 10);
  expect_valid_atlas(m, a, "knight/10");
}

TEST(TextureAtlas, OverlapCounterDetectsOverlap) {
  TextureAtlas a;
  a.UV.resize(6, 2);
  a.UV << 0, 0, 1, 0, 0, 1, 0.2, 0.2, 1.2, 0.2, 0.2, 1.2;
  a.FUV.resize(2, 3);
  a.FUV << 0, 1, 2, 3, 4, 5;
  EXPECT_EQ(count_uv_overlaps(a), 1);
  a.UV.bottomRows(3).col(0).array() += 1.0;  // touching at a point only
  EXPECT_EQ(count_uv_overlaps(a), 0);
}

TEST(TextureAtlas, InvalidInputThrows) {
  const TriMesh m = test::unit_cube();
  TextureAtlasOptions bad;
  bad.cone_cosine = 1.0;
  EXPECT_THROW(texture_atlas(m.V, m.F, bad), InvalidInput);
  EXPECT_THROW(texture_atlas(m.V, MatrixX3i(0, 3)), InvalidInput);
  MatrixX3i F = m.F;
  F(0, 0) = 99;
  EXPECT_THROW(texture_atlas(m.V, F), InvalidInput);
}

}  // namespace
}  // namespace mq
