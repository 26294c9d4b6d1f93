#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/swatch_generators.h"
#include "core/planar/swatch_symmetry.h"

namespace mq {
namespace {

double signed_volume(const TriMesh& m) {
  double v = 0;
  for (int f = 0; f < m.num_faces(); ++f)
    v += m.V.row(m.F(f, 0)).dot(m.V.row(m.F(f, 1)).cross(m.V.row(m.F(f, 2))));
  return v / 6;
}

// Every component closed, manifold, without degenerate faces and of positive volume; returns
// the components.
std::vector<TriMesh> check_elements(const TriMesh& m) {
  EXPECT_EQ(topology_report(m).num_degenerate_faces, 0);
  std::vector<int> fc;
  const int nc = connected_components(m.F, m.num_vertices(), fc);
  std::vector<TriMesh> parts;
  for (const auto& faces : component_faces(fc, nc)) {
    parts.push_back(extract_faces(m, faces));
    const TopologyReport r = topology_report(parts.back());
    EXPECT_TRUE(r.closed()) << "component " << parts.size() - 1;
    EXPECT_TRUE(r.manifold()) << "component " << parts.size() - 1;
    EXPECT_EQ(r.num_components, 1);
    EXPECT_GT(signed_volume(parts.back()), 0) << "component " << parts.size() - 1;
  }
  return parts;
}

// Placed at the origin; thickness (z) is the smallest side.
void check_placement(const TriMesh& m) {
  const BoundingBox box = bounding_box(m.V, m.F);
  EXPECT_NEAR(box.min.norm(), 0.0, 1e-12);
  const Vector3d e = box.extent();
  EXPECT_LT(e.z(), e.x());
  EXPECT_LT(e.z(), e.y());
}

// Point of the ring's wire centre circle: centre + R (cos t e1 + sin t e2) recovered from the
// ring mesh by a plane fit (mean and two principal directions).
struct Circle {
  Vector3d c, e1, e2;
  double R;
};
Circle fit_circle(const TriMesh& ring) {
  Circle k;
  k.c = ring.V.colwise().mean().transpose();
  const MatrixX3d X = ring.V.rowwise() - k.c.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(X.transpose() * X);
  k.e1 = es.eigenvectors().col(2);
  k.e2 = es.eigenvectors().col(1);
  k.R = X.rowwise().norm().mean();
  return k;
}

// Linking test of two circles: the circle b crosses the disc of a exactly once.
int disc_crossings(const Circle& a, const Circle& b) {
  const Vector3d n = a.e1.cross(a.e2);
  int crossings = 0;
  const int N = 720;
  for (int i = 0; i < N; ++i) {
    // Samples a quarter step off the axes: a crossing exactly at a sample (an upright ring's
    // lowest point on the sheet's plane) would otherwise be lost to sin(2 pi) != 0.
    const double t0 = 2 * M_PI * (i + 0.25) / N, t1 = 2 * M_PI * (i + 1.25) / N;
    const Vector3d p = b.c + b.R * (std::cos(t0) * b.e1 + std::sin(t0) * b.e2);
    const Vector3d q = b.c + b.R * (std::cos(t1) * b.e1 + std::sin(t1) * b.e2);
    const double dp = n.dot(p - a.c), dq = n.dot(q - a.c);
    if ((dp < 0) != (dq < 0)) {
      const Vector3d x = p + dp / (dp - dq) * (q - p);
      crossings += (x - a.c).norm() < a.R;
    }
  }
  return crossings;
}

TEST(SwatchGenerators, ChainMailRingsClosedLinkedAndDisjoint) {
  for (const auto& [rows, cols] : {std::pair{3, 4}, std::pair{6, 6}}) {
    ChainMailOptions o;
    o.rows = rows;
    o.cols = cols;
    const TriMesh mail = chainmail_4in1(o);
    EXPECT_GE(mail.num_faces(), 10000 * (rows * cols == 36));
    check_placement(mail);
    const auto rings = check_elements(mail);
    ASSERT_EQ(static_cast<int>(rings.size()), rows * cols);
    EXPECT_TRUE(intersecting_face_pairs(mail.V, mail.F).empty());
    // Rings are generated column by column: ring (c, k) is index c * rows + k. Each links its
    // diagonal neighbours in the next column and does not link its column neighbour.
    std::vector<Circle> circles;
    for (const auto& r : rings) circles.push_back(fit_circle(r));
    int links = 0;
    for (int c = 0; c + 1 < cols; ++c)
      for (int k = 0; k < rows; ++k) {
        const int a = c * rows + k;
        // Odd columns are shifted by +half a pitch: the diagonal neighbours of (c, k).
        const int k0 = (c % 2 == 0) ? k - 1 : k, k1 = k0 + 1;
        for (int kn : {k0, k1}) {
          if (kn < 0 || kn >= rows) continue;
          const int b = (c + 1) * rows + kn;
          EXPECT_EQ(disc_crossings(circles[a], circles[b]), 1) << a << " " << b;
          ++links;
        }
        if (k + 1 < rows) {
          EXPECT_NE(disc_crossings(circles[a], circles[a + 1]), 1);
        }
      }
    EXPECT_EQ(links, (cols - 1) * (2 * rows - 1));
  }
  EXPECT_DOUBLE_EQ(chainmail_period_x(), 2.5);
  EXPECT_DOUBLE_EQ(chainmail_period_y(), 1.25);
}

TEST(SwatchGenerators, ChainMailIsPeriodic) {
  ChainMailOptions o;
  o.rows = 2;
  o.cols = 3;
  const TriMesh mail = chainmail_4in1(o);
  const int per_ring = mail.num_faces() / 6;
  // Ring (2, 0) is ring (0, 0) shifted by one x period.
  const int nv = mail.num_vertices() / 6;
  const MatrixX3d d = mail.V.middleRows(4 * nv, nv) - mail.V.topRows(nv);
  for (int v = 0; v < nv; ++v)
    EXPECT_LT((d.row(v) - Eigen::RowVector3d(chainmail_period_x(o), 0, 0)).norm(), 1e-12);
  EXPECT_EQ(per_ring, 2 * o.ring_segments * o.wire_segments);
}

TEST(SwatchGenerators, ChainMailRejectsBadOptions) {
  ChainMailOptions o;
  o.wire_radius = 0.3;
  EXPECT_THROW(chainmail_4in1(o), InvalidInput);
  o = {};
  o.rows = 0;
  EXPECT_THROW(chainmail_4in1(o), InvalidInput);
  o = {};
  o.ring_segments = 2;
  EXPECT_THROW(chainmail_4in1(o), InvalidInput);
}

// The square 4-in-1 sheet: closed, disjoint rings (at the thickest wire allowed too); each
// connector threaded through exactly the two flat rings it joins and nothing else; flat rings
// linked to no flat ring; a periodic lattice of separate elements with a half turn, so that
// surface --method auto takes the global layout.
TEST(SwatchGenerators, SquareMailConnectorsJoinTwoFlatRingsEach) {
  for (const double wire : {0.12, 0.15}) {
    SCOPED_TRACE(testing::Message() << "wire " << wire);
    SquareMailOptions o;
    o.rows = 3;
    o.cols = 4;
    o.wire_radius = wire;
    o.ring_segments = 32;
    o.wire_segments = 8;
    const TriMesh mail = chainmail_square(o);
    check_placement(mail);
    const auto rings = check_elements(mail);
    const int flat = o.rows * o.cols;
    const int connectors = (o.rows - 1) * o.cols + o.rows * (o.cols - 1);
    ASSERT_EQ(static_cast<int>(rings.size()), flat + connectors);
    EXPECT_TRUE(intersecting_face_pairs(mail.V, mail.F).empty());
    ASSERT_EQ(mail.kinds, (std::vector<std::string>{"ring", "connector"}));
    std::vector<int> fc;
    connected_components(mail.F, mail.num_vertices(), fc);
    const std::vector<int> kind = component_kinds(mail, fc, flat + connectors);
    std::vector<Circle> circles;
    for (const auto& r : rings) circles.push_back(fit_circle(r));
    for (int e = 0; e < flat + connectors; ++e) {
      EXPECT_EQ(kind[e], e < flat ? 0 : 1) << e;
      EXPECT_NEAR(circles[e].R, e < flat ? 1.0 : 0.6, 1e-2) << e;
      // Flat rings lie in the sheet's plane, connectors stand upright.
      EXPECT_NEAR(std::abs(circles[e].e1.cross(circles[e].e2).z()), e < flat ? 1.0 : 0.0, 1e-6);
    }
    // Grid position of a flat ring (c, k): index k * cols + c.
    const double pitch = chainmail_square_period(o);
    EXPECT_DOUBLE_EQ(pitch, 2.5);
    const Vector3d origin = circles[0].c;
    std::vector<int> links(static_cast<size_t>(flat), 0);
    for (int a = flat; a < flat + connectors; ++a) {
      int partners = 0;
      for (int b = 0; b < flat + connectors; ++b) {
        if (b == a) continue;
        const bool linked = disc_crossings(circles[b], circles[a]) % 2 == 1;
        if (b >= flat) {
          EXPECT_FALSE(linked) << "connectors " << a << ", " << b;
          continue;
        }
        // Linked exactly to the flat rings half a pitch away.
        const double d = ((circles[a].c - origin) - (circles[b].c - origin)).head<2>().norm();
        EXPECT_EQ(linked, std::abs(d - 0.5 * pitch) < 1e-6) << a << " " << b;
        partners += linked;
        links[static_cast<size_t>(b)] += linked;
      }
      EXPECT_EQ(partners, 2) << "connector " << a;
    }
    for (int a = 0; a < flat; ++a) {
      const int c = a % o.cols, k = a / o.cols;
      const int expected = (c > 0) + (c + 1 < o.cols) + (k > 0) + (k + 1 < o.rows);
      EXPECT_EQ(links[static_cast<size_t>(a)], expected) << "flat ring " << a;
      for (int b = a + 1; b < flat; ++b) EXPECT_EQ(disc_crossings(circles[a], circles[b]), 0);
    }
  }
  // A lattice of separate elements (one flat ring and two connectors per cell), half-turn
  // symmetric: what the global layout needs.
  SquareMailOptions o;
  o.rows = o.cols = 3;
  o.ring_segments = 16;
  o.wire_segments = 4;
  const PreparedSwatch swatch = prepare_swatch(chainmail_square(o));
  const SwatchFaceTree tree(swatch.mesh.V, swatch.mesh.F);
  const SwatchSymmetry sym = detect_swatch_symmetry(swatch, tree, matching_cell_size(swatch));
  ASSERT_TRUE(sym.periodic);
  EXPECT_NEAR(std::abs(sym.a.x() * sym.b.y() - sym.a.y() * sym.b.x()), 2.5 * 2.5, 1e-3);
  EXPECT_NEAR(std::min(sym.a.norm(), sym.b.norm()), 2.5, 1e-3);
  EXPECT_TRUE(sym.half_turn);
  EXPECT_TRUE(repeating_elements(swatch));
  EXPECT_TRUE(tileable(swatch, sym));
  int orbits = 0;
  tile_lattice(swatch, sym, Vector2d::Zero(), Vector2d(10, 10), &orbits);
  EXPECT_EQ(orbits, 3);
}

TEST(SwatchGenerators, SquareMailRejectsBadOptions) {
  SquareMailOptions o;
  o.wire_radius = 0.16;
  EXPECT_THROW(chainmail_square(o), InvalidInput);
  o = {};
  o.cols = 0;
  EXPECT_THROW(chainmail_square(o), InvalidInput);
  o = {};
  o.wire_segments = 2;
  EXPECT_THROW(chainmail_square(o), InvalidInput);
  o = {};
  o.ring_radius = 0;
  EXPECT_THROW(chainmail_square_period(o), InvalidInput);
}

TEST(SwatchGenerators, WeaveThreadsClosedDisjointAndAlternating) {
  WeaveOptions o;
  o.threads_x = 5;
  o.threads_y = 4;
  const TriMesh cloth = plain_weave(o);
  check_placement(cloth);
  const auto threads = check_elements(cloth);
  ASSERT_EQ(static_cast<int>(threads.size()), 9);
  EXPECT_TRUE(intersecting_face_pairs(cloth.V, cloth.F).empty());
  // Heights at crossings: warp j (along x) and weft i (along y) cross above (i s, j s) plus the
  // placement offset, read off the centre lines of weft 0 (x) and warp 0 (y).
  const BoundingBox box = bounding_box(cloth.V);
  const Vector2d off(threads[o.threads_x].V.col(0).mean(), threads[0].V.col(1).mean());
  for (int j = 0; j < o.threads_x; ++j)
    for (int i = 0; i < o.threads_y; ++i) {
      const Vector2d X = off + o.spacing * Vector2d(i, j);
      const auto mean_z_near = [&](const TriMesh& t) {
        double z = 0;
        int n = 0;
        for (int v = 0; v < t.num_vertices(); ++v)
          if ((t.V.row(v).head<2>().transpose() - X).norm() < 0.5 * o.thread_radius) {
            z += t.V(v, 2);
            ++n;
          }
        EXPECT_GT(n, 0);
        return z / std::max(n, 1);
      };
      const double warp = mean_z_near(threads[j]), weft = mean_z_near(threads[o.threads_x + i]);
      const bool warp_over = (i + j) % 2 == 0;
      EXPECT_EQ(warp > weft, warp_over) << "crossing " << i << " " << j;
    }
  EXPECT_GT(cloth.num_faces(), 0);
  EXPECT_LE(box.extent().z(), 2 * (1.2 + 1) * o.thread_radius + 1e-9);
  WeaveOptions bad;
  bad.thread_radius = 0.5;
  EXPECT_THROW(plain_weave(bad), InvalidInput);
}

TEST(SwatchGenerators, AppleLayerClosedDisjointOnThePlane) {
  for (uint64_t seed : {1u, 7u}) {
    for (int count : {5, 24}) {
      AppleOptions o;
      o.seed = seed;
      o.count = count;
      const TriMesh layer = apple_layer(o);
      check_placement(layer);
      const auto apples = check_elements(layer);
      ASSERT_EQ(static_cast<int>(apples.size()), count);
      EXPECT_TRUE(intersecting_face_pairs(layer.V, layer.F).empty());
      for (const auto& a : apples) EXPECT_NEAR(a.V.col(2).minCoeff(), 0.0, 1e-12);
      if (count == 24) {
        EXPECT_GE(layer.num_faces(), 4000);
        EXPECT_LE(layer.num_faces(), 10000);
      }
    }
  }
  AppleOptions o;
  const TriMesh a = apple_layer(o), b = apple_layer(o);
  EXPECT_EQ(a.V, b.V);
  o.seed = 2;
  EXPECT_NE(apple_layer(o).V, a.V);
  o.resolution = 3;
  EXPECT_THROW(apple_layer(o), InvalidInput);
}

TEST(SwatchGenerators, IvyClosedDeterministicAndSeeded) {
  IvyOptions o;
  const TriMesh ivy = ivy_section(o);
  check_placement(ivy);
  const auto parts = check_elements(ivy);
  EXPECT_EQ(static_cast<int>(parts.size()), 1 + o.leaves);
  EXPECT_TRUE(intersecting_face_pairs(ivy.V, ivy.F).empty());
  EXPECT_LE(ivy.num_faces(), 8000);
  const TriMesh again = ivy_section(o);
  EXPECT_EQ(again.V, ivy.V);
  EXPECT_EQ(again.F, ivy.F);
  o.seed = 99;
  const TriMesh other = ivy_section(o);
  EXPECT_FALSE(other.V.rows() == ivy.V.rows() && other.V == ivy.V);
  o.leaf_size = 0;
  EXPECT_THROW(ivy_section(o), InvalidInput);
}

}  // namespace
}  // namespace mq
