#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "core/errors.h"
#include "core/geometry_measures.h"
#include "core/mesh_intersections.h"
#include "core/mesh_topology.h"
#include "core/swatch_generators.h"

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
    const double t0 = 2 * M_PI * i / N, t1 = 2 * M_PI * (i + 1) / N;
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
