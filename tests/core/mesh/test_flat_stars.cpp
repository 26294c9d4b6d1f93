#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/mesh/flat_stars.h"
#include "core/mesh/mesh_intersections.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// A fan of k faces round vertex 0 (at the origin): ring vertex i at angle[i], radius r[i] and
// height z[i]; closed (a cycle) or open (a chain from the first to the last ring vertex).
TriMesh fan(const std::vector<double>& angle, const std::vector<double>& r,
            const std::vector<double>& z, bool closed) {
  const int k = static_cast<int>(angle.size());
  TriMesh m;
  m.V.resize(k + 1, 3);
  m.V.row(0) << 0, 0, 0;
  for (int i = 0; i < k; ++i)
    m.V.row(i + 1) << r[i] * std::cos(angle[i]), r[i] * std::sin(angle[i]), z[i];
  const int faces = closed ? k : k - 1;
  m.F.resize(faces, 3);
  for (int i = 0; i < faces; ++i) m.F.row(i) << 0, 1 + i, 1 + (i + 1) % k;
  return m;
}

// Segment pq against triangle abc, written out independently of the library (Moller-Trumbore
// with the segment's parameter in [0, 1]): whether they meet, with a small margin either way.
bool segment_meets_triangle(const Vector3d& p, const Vector3d& q, const Vector3d& a,
                            const Vector3d& b, const Vector3d& c) {
  const Vector3d d = q - p, e1 = b - a, e2 = c - a, h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-14) return false;  // parallel: the fans below are never coplanar
  const Vector3d s = p - a;
  const double u = s.dot(h) / det;
  const Vector3d qv = s.cross(e1);
  const double v = d.dot(qv) / det, t = e2.dot(qv) / det;
  return u >= -1e-9 && v >= -1e-9 && u + v <= 1 + 1e-9 && t >= -1e-9 && t <= 1 + 1e-9;
}

// Whether two faces of a fan that share only the centre meet elsewhere: the edge opposite the
// centre of either crosses the other face.
bool meet_beyond_centre(const TriMesh& m, int f, int g) {
  const auto P = [&](int face, int k) -> Vector3d { return m.V.row(m.F(face, k)).transpose(); };
  return segment_meets_triangle(P(f, 1), P(f, 2), P(g, 0), P(g, 1), P(g, 2)) ||
         segment_meets_triangle(P(g, 1), P(g, 2), P(f, 0), P(f, 1), P(f, 2));
}

TEST(FlatStars, SmoothClosedSurfacesAreFlatEverywhere) {
  for (const TriMesh& m : {test::torus(1.0, 0.3, 32, 12), test::uv_sphere(1.0, 24, 12)}) {
    const std::vector<char> flat = flat_stars(m.V, m.F);
    int count = 0;
    for (const char c : flat) count += c;
    // The sphere's two poles have 24 thin faces each: flat too.
    EXPECT_EQ(count, m.num_vertices());
  }
}

TEST(FlatStars, BordersOfAFlatSheetAreJudgedConservatively) {
  const TriMesh grid = test::plane_grid(1.0, 1.0, 4, 4);  // 5 x 5 vertices
  const std::vector<char> flat = flat_stars(grid.V, grid.F);
  for (int v = 0; v < grid.num_vertices(); ++v) {
    const double x = grid.V(v, 0), y = grid.V(v, 1);
    const bool corner = (std::abs(x) < 1e-12 || std::abs(x - 1) < 1e-12) &&
                        (std::abs(y) < 1e-12 || std::abs(y - 1) < 1e-12);
    // Interior and edge vertices (a half turn) are flat; a corner's gap of 270 or 90 degrees is
    // left to the exact test or judged flat, never wrongly.
    if (!corner) {
      EXPECT_TRUE(flat[static_cast<size_t>(v)]) << v;
    }
  }
}

TEST(FlatStars, FoldedFansAreNotFlat) {
  // Sectors that turn back (a face flipped over its neighbours), that wind twice, or a chain
  // that closes over its own start, all with faces that really cross.
  const std::vector<double> r(8, 1.0), z(8, 0.0);
  std::vector<double> turning_back = {0, 0.8, 1.6, 1.2, 2.4, 3.2, 4.0, 4.8};
  std::vector<double> twice;
  for (int i = 0; i < 8; ++i) twice.push_back(i * 2 * kTwoPi / 8 + 0.01);
  std::vector<double> overlapping_chain;
  for (int i = 0; i < 8; ++i) overlapping_chain.push_back(i * 1.1);  // 7.7 rad > a turn
  const std::vector<double> small_z = {0, 0.01, -0.01, 0.02, 0, 0.01, -0.02, 0.01};
  EXPECT_FALSE(
      flat_stars(fan(turning_back, r, small_z, true).V, fan(turning_back, r, small_z, true).F)[0]);
  EXPECT_FALSE(flat_stars(fan(twice, r, small_z, true).V, fan(twice, r, small_z, true).F)[0]);
  EXPECT_FALSE(flat_stars(fan(overlapping_chain, r, small_z, false).V,
                          fan(overlapping_chain, r, small_z, false).F)[0]);
  // And a flat fan of the same rings is flat.
  std::vector<double> once;
  for (int i = 0; i < 8; ++i) once.push_back(i * kTwoPi / 8);
  EXPECT_TRUE(flat_stars(fan(once, r, z, true).V, fan(once, r, z, true).F)[0]);
  // Two fans sharing the centre (a bowtie of cones) are not one star.
  TriMesh two = fan(once, r, z, true);
  const Eigen::Index n = two.V.rows(), nf = two.F.rows();
  two.V.conservativeResize(2 * n - 1, 3);
  two.F.conservativeResize(2 * nf, 3);
  for (Eigen::Index i = 1; i < n; ++i)
    two.V.row(n - 1 + i) = two.V.row(i) + Vector3d(0, 0, 1).transpose();
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      two.F(nf + f, k) = two.F(f, k) == 0 ? 0 : static_cast<int>(two.F(f, k) + n - 1);
  EXPECT_FALSE(flat_stars(two.V, two.F)[0]);
}

// The property the intersection test relies on, against an independent segment test: in every
// random fan judged flat, no two faces sharing only the centre meet beyond it; and the
// intersection test finds the same pairs as that independent test on every fan, flat or not.
TEST(FlatStars, FlatFansNeverCrossAndTheIntersectionTestAgreesEitherWay) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int flat_fans = 0, crossing_fans = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int k = 3 + static_cast<int>(unit(rng) * 14);
    const bool closed = unit(rng) < 0.7;
    const double spread = (closed ? kTwoPi : 4.0) * (0.6 + unit(rng));  // sometimes past a turn
    std::vector<double> angle, r, z;
    double a = 0;
    for (int i = 0; i < k; ++i) {
      angle.push_back(a);
      // Mostly forward, now and then back: folds.
      a += spread / k * (unit(rng) < 0.1 ? -0.7 : 0.3 + 1.4 * unit(rng));
      r.push_back(0.3 + unit(rng));
      z.push_back((unit(rng) - 0.5) * (unit(rng) < 0.5 ? 0.3 : 3.0));
    }
    const TriMesh m = fan(angle, r, z, closed);
    const bool flat = flat_stars(m.V, m.F)[0] != 0;
    flat_fans += flat;
    std::vector<std::pair<int, int>> crossing;
    for (int f = 0; f < m.num_faces(); ++f)
      for (int g = f + 1; g < m.num_faces(); ++g) {
        int shared = 0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) shared += m.F(f, i) == m.F(g, j);
        if (shared == 1 && meet_beyond_centre(m, f, g)) crossing.emplace_back(f, g);
      }
    crossing_fans += !crossing.empty();
    if (flat) {
      EXPECT_TRUE(crossing.empty()) << "trial " << trial;
    }
    // Pairs sharing an edge are the library's alone (coplanar fold-overs); compare the rest.
    IntersectionOptions all;
    all.between_components_only = false;
    std::vector<std::pair<int, int>> found;
    for (const auto& [f, g] : intersecting_face_pairs(m.V, m.F, all)) {
      int shared = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) shared += m.F(f, i) == m.F(g, j);
      if (shared == 1) found.emplace_back(f, g);
    }
    EXPECT_EQ(found, crossing) << "trial " << trial;
  }
  // Both kinds were generated.
  EXPECT_GT(flat_fans, 300);
  EXPECT_GT(crossing_fans, 300);
}

}  // namespace
}  // namespace mq
