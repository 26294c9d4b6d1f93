// Property checks of a planar quilting result, shared by the fast tests (tests/core) and the
// realistic-size runs (tests/slow).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/quilt_elements.h"
#include "core/planar/swatch_generators.h"

namespace mq::test {

// Small procedural swatches: a few elements with coarse tessellation, so a quilt takes seconds.
inline TriMesh small_chainmail(int rings = 3) {
  ChainMailOptions o;
  o.rows = rings;
  o.cols = rings;
  o.ring_segments = 24;
  o.wire_segments = 8;
  return chainmail_4in1(o);
}
// Coarser still (3 x 3 rings, 16 x 6 segments), for surface runs.
inline TriMesh tiny_chainmail() {
  ChainMailOptions o;
  o.rows = 3;
  o.cols = 3;
  o.ring_segments = 16;
  o.wire_segments = 6;
  return chainmail_4in1(o);
}
inline TriMesh small_weave() {
  WeaveOptions o;
  o.threads_x = 4;
  o.threads_y = 4;
  o.segments_per_cell = 8;
  o.tube_segments = 6;
  return plain_weave(o);
}
inline TriMesh small_apples(int count = 8) {
  AppleOptions o;
  o.count = count;
  o.resolution = 8;
  return apple_layer(o);
}
inline TriMesh small_ivy() {
  IvyOptions o;
  o.length = 5;
  o.leaves = 5;
  return ivy_section(o);
}

// The connected components of a mesh, each as its own mesh.
inline std::vector<TriMesh> components(const TriMesh& m) {
  std::vector<int> fc;
  const int n = connected_components(m.F, m.num_vertices(), fc);
  std::vector<TriMesh> parts;
  for (const auto& faces : component_faces(fc, n)) parts.push_back(extract_faces(m, faces));
  return parts;
}

// Fraction of [lo, hi] covered by the xy projection of the triangles, sampled at the centres of
// an n by n raster (a point counts when it lies in some projected triangle).
inline double projected_coverage(const TriMesh& m, const Vector2d& lo, const Vector2d& hi,
                                 int n = 400) {
  std::vector<unsigned char> hit(static_cast<size_t>(n) * n, 0);
  const double dx = (hi.x() - lo.x()) / n, dy = (hi.y() - lo.y()) / n;
  for (int f = 0; f < m.num_faces(); ++f) {
    Vector2d p[3];
    for (int k = 0; k < 3; ++k) p[k] = m.V.row(m.F(f, k)).head<2>().transpose();
    const double area =
        (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    if (area == 0) continue;
    const double x0 = std::min({p[0].x(), p[1].x(), p[2].x()}),
                 x1 = std::max({p[0].x(), p[1].x(), p[2].x()});
    const double y0 = std::min({p[0].y(), p[1].y(), p[2].y()}),
                 y1 = std::max({p[0].y(), p[1].y(), p[2].y()});
    const int i0 = std::max(0, static_cast<int>(std::floor((x0 - lo.x()) / dx - 0.5)));
    const int i1 = std::min(n - 1, static_cast<int>(std::ceil((x1 - lo.x()) / dx - 0.5)));
    const int j0 = std::max(0, static_cast<int>(std::floor((y0 - lo.y()) / dy - 0.5)));
    const int j1 = std::min(n - 1, static_cast<int>(std::ceil((y1 - lo.y()) / dy - 0.5)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const Vector2d q(lo.x() + (i + 0.5) * dx, lo.y() + (j + 0.5) * dy);
        double s[3];
        for (int k = 0; k < 3; ++k) {
          const Vector2d a = p[k], b = p[(k + 1) % 3];
          s[k] = ((b - a).x() * (q - a).y() - (b - a).y() * (q - a).x()) * (area > 0 ? 1 : -1);
        }
        if (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) hit[static_cast<size_t>(j) * n + i] = 1;
      }
  }
  return static_cast<double>(std::count(hit.begin(), hit.end(), 1)) / hit.size();
}

// Footprint diameters (xy bounding-box diagonal) of the elements.
inline std::vector<double> footprint_diameters(const std::vector<TriMesh>& parts) {
  std::vector<double> d;
  for (const TriMesh& p : parts) {
    const BoundingBox b = bounding_box(p.V, p.F);
    d.push_back((b.max - b.min).head<2>().norm());
  }
  return d;
}

struct QuiltExpectations {
  bool check_diameters = true;  // every element within a factor 2 of the swatch elements'
  bool check_coverage = true;   // coverage within 10% (relative) of the swatch's
  double coverage_tolerance = 0.10;
};

// The properties every planar quilt of a swatch of closed, non-intersecting elements must have.
inline void expect_valid_quilt(const TriMesh& swatch, const TriMesh& out, double L, double W,
                               const QuiltExpectations& expect = {}) {
  ASSERT_GT(out.num_faces(), 0);
  const TopologyReport whole = topology_report(out);
  EXPECT_EQ(whole.num_boundary_edges, 0) << "elements must stay closed";
  EXPECT_EQ(whole.num_non_manifold_edges, 0);
  const std::vector<TriMesh> parts = components(out);
  int open = 0, non_manifold = 0, outside = 0;
  for (size_t i = 0; i < parts.size(); ++i) {
    const TopologyReport r = topology_report(parts[i]);
    open += !r.closed();
    non_manifold += !r.manifold();
    const BoundingBox b = bounding_box(parts[i].V, parts[i].F);
    // Whole elements may cross the border but each must meet the domain.
    outside += b.max.x() < 0 || b.min.x() > L || b.max.y() < 0 || b.min.y() > W;
  }
  EXPECT_EQ(open, 0) << "of " << parts.size() << " elements";
  EXPECT_EQ(non_manifold, 0) << "of " << parts.size() << " elements";
  EXPECT_EQ(outside, 0) << "of " << parts.size() << " elements";
  const auto pairs = intersecting_face_pairs(out.V, out.F);
  EXPECT_TRUE(pairs.empty()) << pairs.size() << " intersecting face pairs between elements";

  if (expect.check_diameters) {
    const std::vector<double> ds = footprint_diameters(components(swatch));
    const double lo = *std::min_element(ds.begin(), ds.end());
    const double hi = *std::max_element(ds.begin(), ds.end());
    int off = 0;
    for (const double d : footprint_diameters(parts)) off += d < 0.5 * lo || d > 2 * hi;
    EXPECT_EQ(off, 0) << "elements with a footprint outside [" << 0.5 * lo << ", " << 2 * hi << "]";
  }
  if (expect.check_coverage) {
    // The swatch's density is taken both over its whole footprint and over its interior (a
    // quarter of the mean element diameter, at most a quarter of its shorter side, from the
    // border): a swatch's border has gaps of its own (the staggered columns of a chain mail sheet
    // leave empty corners, dart-thrown apples thin out towards the edges), and a grown layer may
    // match either value. The output, measured over the domain's interior, must lie within the
    // tolerance of the range between them.
    const BoundingBox b = bounding_box(swatch.V, swatch.F);
    const std::vector<double> ds = footprint_diameters(components(swatch));
    double mean = 0;
    for (const double d : ds) mean += d / ds.size();
    const double margin = std::min(0.25 * mean, 0.25 * b.extent().head<2>().minCoeff());
    const double whole = projected_coverage(swatch, b.min.head<2>(), b.max.head<2>());
    const double interior = projected_coverage(swatch, b.min.head<2>().array() + margin,
                                               b.max.head<2>().array() - margin);
    const double got =
        projected_coverage(out, Vector2d(margin, margin), Vector2d(L - margin, W - margin));
    const double tol = expect.coverage_tolerance;
    EXPECT_GE(got, (1 - tol) * std::min(whole, interior))
        << "domain coverage " << got << " vs the swatch's " << whole << " (whole) and " << interior
        << " (interior)";
    EXPECT_LE(got, (1 + tol) * std::max(whole, interior))
        << "domain coverage " << got << " vs the swatch's " << whole << " (whole) and " << interior
        << " (interior)";
  }
}

}  // namespace mq::test
