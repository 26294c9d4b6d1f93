#include <gtest/gtest.h>

#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"
#include "core/surface/global_parameterization.h"
#include "core/surface/line_field.h"
#include "core/surface/tangent_field.h"
#include "tests/core/shell_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

struct Solved {
  TriMesh mesh;
  EdgeTopology topo;
  MatrixX3i TT;
  DirectionField field;
  GlobalParameterization gp;
};

Solved solve(TriMesh mesh, const Vector3d* direction = nullptr) {
  Solved s;
  s.mesh = std::move(mesh);
  s.topo = edge_topology(s.mesh.F, s.mesh.num_vertices());
  s.TT = face_adjacency(s.topo);
  const MatrixX3d guide = direction ? tangent_field_from_direction(s.mesh.V, s.mesh.F, *direction)
                                    : smooth_tangent_field(s.mesh.V, s.mesh.F);
  LineFieldOptions o;
  o.guidance_weight = direction ? 1.0 : 1e-3;
  s.field = smooth_direction_field(s.mesh.V, s.mesh.F, s.topo, s.TT, guide, o);
  s.gp = global_parameterization(s.mesh.V, s.mesh.F, s.topo, s.TT, s.field);
  return s;
}

TEST(GlobalParameterization, FlatGridIsUnfoldedIsometricallyAlongTheField) {
  const Vector3d x = Vector3d::UnitX();
  const Solved s = solve(test::plane_grid(3, 2, 9, 6), &x);
  EXPECT_EQ(s.gp.num_cut_edges, 0);
  EXPECT_EQ(s.gp.num_singular, 0);
  // u along x, v along y (up to a common translation and the line field's sign).
  const Vector2d o = s.gp.uv(0, 0);
  const Vector3d p0 = s.mesh.V.row(s.mesh.F(0, 0));
  for (int f = 0; f < s.mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Vector3d d = s.mesh.V.row(s.mesh.F(f, k)).transpose() - p0;
      const Vector2d g = s.gp.uv(f, k) - o;
      EXPECT_NEAR(std::abs(g.x()), std::abs(d.x()), 1e-6);
      EXPECT_NEAR(std::abs(g.y()), std::abs(d.y()), 1e-6);
      EXPECT_NEAR(g.norm(), d.norm(), 1e-6);
    }
}

TEST(GlobalParameterization, OpenCylinderIsCutOnceAndUnrolledAtUnitScale) {
  const double r = 1.0;
  const Vector3d axis = Vector3d::UnitZ();
  const Solved s = solve(test::open_cylinder(r, 2.0, 48, 12), &axis);
  EXPECT_EQ(s.gp.num_singular, 0);
  // One path from one boundary to the other: as many cut edges as rows of faces.
  EXPECT_EQ(s.gp.num_cut_edges, 12);
  const std::vector<CutPath> paths = cut_paths(s.gp, s.topo, s.mesh.F);
  ASSERT_EQ(paths.size(), 1u);
  EXPECT_EQ(paths[0].sign, 1);
  // Its transition is the translation by the circumference across the axis.
  const Vector2d t = path_translation(s.gp, s.topo, s.mesh.F, paths[0]);
  const double circumference = 48 * 2 * r * std::sin(M_PI / 48);
  EXPECT_NEAR(t.norm(), circumference, 1e-3 * circumference);
  EXPECT_NEAR(std::abs(t.x()), 0.0, 1e-3);
  // And every face keeps its area.
  for (int f = 0; f < s.mesh.num_faces(); ++f) {
    const Vector2d a = s.gp.uv(f, 0), b = s.gp.uv(f, 1), c = s.gp.uv(f, 2);
    const double a2 = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    const Vector3d p = s.mesh.V.row(s.mesh.F(f, 0)), q = s.mesh.V.row(s.mesh.F(f, 1)),
                   w = s.mesh.V.row(s.mesh.F(f, 2));
    EXPECT_NEAR(a2, 0.5 * (q - p).cross(w - p).norm(), 1e-3 * a2);
  }
}

TEST(GlobalParameterization, SphereChartsMeetAlongCutsToItsFourCones) {
  const Solved s = solve(test::icosphere(4));
  EXPECT_EQ(s.gp.num_singular, 4);
  EXPECT_GT(s.gp.num_cut_edges, 0);
  // A patch around a face away from the cones unfolds consistently, across cuts too, and
  // without flipped triangles.
  int tried = 0, unfolded = 0;
  for (int seed = 0; seed < s.mesh.num_faces(); seed += 97) {
    bool near_cone = false;
    std::vector<int> faces = {seed};
    std::vector<char> in(static_cast<size_t>(s.mesh.num_faces()), 0);
    in[seed] = 1;
    for (size_t i = 0; i < faces.size() && faces.size() < 60; ++i)
      for (int k = 0; k < 3; ++k) {
        const int g = s.TT(faces[i], k);
        if (g >= 0 && !in[g]) {
          in[g] = 1;
          faces.push_back(g);
        }
      }
    for (const int f : faces)
      for (int k = 0; k < 3; ++k) near_cone = near_cone || s.gp.singular[s.mesh.F(f, k)];
    if (near_cone) continue;
    const TriMesh patch = extract_faces(s.mesh, faces);
    MatrixX2d uv;
    ++tried;
    if (!unfold_patch(s.gp, s.topo, s.TT, s.mesh.V, s.mesh.F, faces, patch.F, patch.num_vertices(),
                      uv))
      continue;
    ++unfolded;
    int flipped = 0;
    for (int f = 0; f < patch.num_faces(); ++f) {
      const Vector2d a = uv.row(patch.F(f, 0)), b = uv.row(patch.F(f, 1)),
                     c = uv.row(patch.F(f, 2));
      flipped += (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x() < 0;
    }
    EXPECT_EQ(flipped, 0) << "seed " << seed;
  }
  EXPECT_GT(tried, 40);
  EXPECT_EQ(unfolded, tried);
}

TEST(GlobalParameterization, LocateWalksAcrossCutsToThePoint) {
  const Solved s = solve(test::icosphere(4));
  // From each face, the centroid of a neighbour across each edge, given in the neighbour's
  // chart and carried into this face's chart by the transition, is found in that neighbour.
  int cut_crossings = 0;
  for (int f = 0; f < s.mesh.num_faces(); f += 7)
    for (int k = 0; k < 3; ++k) {
      const int g = s.TT(f, k);
      if (g < 0) continue;
      const int e = s.topo.FE(f, k);
      // The neighbour's centroid in f's chart: through the shared edge's end points.
      Vector2d target = (s.gp.uv(g, 0) + s.gp.uv(g, 1) + s.gp.uv(g, 2)) / 3.0;
      if (s.gp.cut[e]) {
        ++cut_crossings;
        const double sg = s.gp.sign[e];
        // uv_g = sg uv_f + t at the shared vertices, so uv_f = sg (uv_g - t).
        Vector2d t = Vector2d::Zero();
        for (int side = 0; side < 2; ++side) {
          const int v = s.topo.E(e, side);
          int cg = 0, cf = 0;
          for (int c = 0; c < 3; ++c) {
            if (s.mesh.F(g, c) == v) cg = c;
            if (s.mesh.F(f, c) == v) cf = c;
          }
          const bool g_second = s.topo.edge_faces.begin(e)[1] == g;
          t += g_second ? Vector2d(s.gp.uv(g, cg) - sg * s.gp.uv(f, cf))
                        : Vector2d(s.gp.uv(f, cf) - sg * s.gp.uv(g, cg));
        }
        t *= 0.5;
        const bool g_second = s.topo.edge_faces.begin(e)[1] == g;
        target = g_second ? Vector2d(sg * (target - t)) : Vector2d(sg * target + t);
      }
      int face = f;
      Vector2d x = target;
      Vector3d b;
      ASSERT_TRUE(locate_in_charts(s.gp, s.topo, s.TT, s.mesh.F, face, x, b));
      EXPECT_EQ(face, g);
      EXPECT_NEAR(b.minCoeff(), 1.0 / 3.0, 1e-3);
    }
  EXPECT_GT(cut_crossings, 0);
}

TEST(GlobalParameterization, OptionsWithoutPositiveWeightsAreRefused) {
  GlobalParameterizationOptions o;
  EXPECT_NO_THROW(o.validate());
  o.cut_weight = 0;
  EXPECT_THROW(o.validate(), InvalidInput);
  o.cut_weight = 1;
  o.pin_weight = std::nan("");
  EXPECT_THROW(o.validate(), InvalidInput);
}

}  // namespace
}  // namespace mq
