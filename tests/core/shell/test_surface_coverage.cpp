#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "core/shell/surface_coverage.h"
#include "tests/test_support.h"

namespace mq {
namespace {

TriMesh moved(TriMesh m, const Vector3d& by) {
  m.V.rowwise() += by.transpose();
  return m;
}

TEST(SurfaceCoverage, OnlyGeometryOnTheOuterSideCounts) {
  // A 1 x 1 sheet facing +z; a sheet of texture just above it covers it, the same just under
  // it does not.
  const TriMesh base = test::plane_grid(1, 1, 10, 10);
  const TriMesh above = moved(test::plane_grid(1, 1, 4, 4), Vector3d(0, 0, 0.05));
  const TriMesh under = moved(above, Vector3d(0, 0, -0.1));
  EXPECT_DOUBLE_EQ(surface_coverage(base, above, 0.1), 1.0);
  EXPECT_DOUBLE_EQ(surface_coverage(base, under, 0.1), 0.0);
  // Under by less than `below`: counted.
  EXPECT_DOUBLE_EQ(surface_coverage(base, under, 0.1, 0.06), 1.0);
  // Half of it: the left half of the texture, close over it (the next centroids are 1/30 away).
  TriMesh half = above;
  half.V.col(0) *= 0.5;
  half.V.col(2).setConstant(0.005);
  EXPECT_NEAR(surface_coverage(base, half, 0.01), 0.5, 1e-9);
  EXPECT_EQ(surface_coverage(base, TriMesh(), 0.1), 0.0);
}

TEST(SurfaceCoverage, ATriangleReachingOverTheBaseFromBelowCountsByItsPartAbove) {
  // One output triangle standing across the base's plane, its part above within the radius of
  // the centroids near it only.
  const TriMesh base = test::plane_grid(1, 1, 1, 1);  // two triangles, centroids at z = 0
  TriMesh wall;
  wall.V.resize(3, 3);
  wall.V << 0, 0.5, -1, 1, 0.5, -1, 0.5, 0.5, 0.02;
  wall.F.resize(1, 3);
  wall.F << 0, 1, 2;
  // Its tip is 0.02 above the plane; the centroids (1/3, 2/3) and (2/3, 1/3) lie 0.236 from the
  // part above (x near 0.5, y = 0.5): covered with radius 0.25, not with 0.2 (the whole
  // triangle comes within 0.2 of them, under the plane).
  EXPECT_DOUBLE_EQ(surface_coverage(base, wall, 0.25), 1.0);
  EXPECT_DOUBLE_EQ(surface_coverage(base, wall, 0.2), 0.0);
}

TEST(SurfaceCoverage, ByTheOutputsVerticesOrItsTrianglesAlike) {
  // The vertices decide first, the triangles where none is near. One large triangle over a
  // 1 x 1 sheet, its corners far beyond the radius of every centroid: covered through its
  // interior. A vertex no face uses, just over the sheet, covers nothing.
  const TriMesh base = test::plane_grid(1, 1, 10, 10);
  TriMesh big;
  big.V.resize(4, 3);
  big.V << -5, -5, 0.02, 10, -5, 0.02, -5, 10, 0.02, 0.5, 0.5, 0.01;
  big.F.resize(1, 3);
  big.F << 0, 1, 2;
  EXPECT_DOUBLE_EQ(surface_coverage(base, big, 0.05), 1.0);
  TriMesh far_face = big;
  far_face.V.topRows(3).col(2).setConstant(3.0);  // the face far above; vertex 3 unused
  EXPECT_DOUBLE_EQ(surface_coverage(base, far_face, 0.05), 0.0);
  // Dense vertices over the left half, the big triangle over all of it under the plane by more
  // than `below`: the left half (its next centroids lie 1/30 beyond the sheet's edge).
  TriMesh both = moved(test::plane_grid(0.5, 1, 20, 40), Vector3d(0, 0, 0.01));
  TriMesh under = big;
  under.V.col(2).setConstant(-0.05);
  append_mesh(both, under);
  EXPECT_NEAR(surface_coverage(base, both, 0.02, 0.01), 0.5, 1e-9);
}

TEST(SurfaceCoverage, ClosedBaseIndependentOfThreads) {
  const TriMesh cube = test::unit_cube();
  // Texture over the top face only (outside), and a copy of the cube shrunk inside.
  TriMesh texture = moved(test::plane_grid(1, 1, 3, 3), Vector3d(0, 0, 1.05));
  TriMesh inner = test::unit_cube();
  inner.V = (inner.V.array() * 0.96 + 0.02).matrix();
  append_mesh(texture, inner);
  double a = 0, b = 0;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    a = surface_coverage(cube, texture, 0.1);
  }
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    b = surface_coverage(cube, texture, 0.1);
  }
  EXPECT_EQ(a, b);
  EXPECT_NEAR(a, 1.0 / 6.0, 1e-12);  // the top face's two triangles, of twelve equal ones
  EXPECT_THROW(surface_coverage(cube, texture, -1), InvalidInput);
  EXPECT_THROW(surface_coverage(cube, texture, 0.1, -1), InvalidInput);
  EXPECT_THROW(surface_coverage(TriMesh(), texture, 0.1), InvalidInput);
}

TEST(SurfaceCoverage, OverTheMaskedFacesOnly) {
  // The cube's top face covered, nothing else: over the top alone 1, over top and bottom 1/2,
  // over the bottom 0 (issue 25: a masked quilt is judged over its mask).
  const TriMesh cube = test::unit_cube();
  const TriMesh texture = moved(test::plane_grid(1, 1, 3, 3), Vector3d(0, 0, 1.05));
  std::vector<char> top(12, 0), bottom(12, 0);
  for (int f = 0; f < 12; ++f) {
    const double z = (cube.V(cube.F(f, 0), 2) + cube.V(cube.F(f, 1), 2) + cube.V(cube.F(f, 2), 2));
    top[f] = z == 3;
    bottom[f] = z == 0;
  }
  std::vector<char> both = top;
  for (int f = 0; f < 12; ++f) both[f] = top[f] || bottom[f];
  EXPECT_DOUBLE_EQ(surface_coverage(cube, texture, 0.1, 0, top), 1.0);
  EXPECT_DOUBLE_EQ(surface_coverage(cube, texture, 0.1, 0, both), 0.5);
  EXPECT_DOUBLE_EQ(surface_coverage(cube, texture, 0.1, 0, bottom), 0.0);
  EXPECT_DOUBLE_EQ(surface_coverage(cube, texture, 0.1, 0, std::vector<char>(12, 0)), 0.0);
  EXPECT_THROW(surface_coverage(cube, texture, 0.1, 0, std::vector<char>(11, 1)), InvalidInput);
}

TEST(SurfaceCoverage, WhatASwatchCoversOfItself) {
  // Chain mail covers its footprint; vines and leaves only part of theirs.
  EXPECT_GT(swatch_coverage(chainmail_4in1()), 0.99);
  const double ivy = swatch_coverage(ivy_section());
  EXPECT_GT(ivy, 0.2);
  EXPECT_LT(ivy, 0.9);
}

}  // namespace
}  // namespace mq
