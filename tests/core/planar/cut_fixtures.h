// Procedural fixtures shared by the element cut and stitch tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/point_triangle.h"
#include "core/planar/element_cut.h"

namespace mq::test {

// Tube of radius r along x over [x0, x1]: nx rings of quads by nt around, outward oriented,
// ring angles shifted by `phase`; optionally closed by a fan at each end.
inline TriMesh tube(double x0, double x1, int nx, int nt, double r, double phase, bool capped) {
  TriMesh m;
  const int nv = (nx + 1) * nt + (capped ? 2 : 0);
  m.V.resize(nv, 3);
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j < nt; ++j) {
      const double t = 2 * M_PI * j / nt + phase;
      m.V.row(i * nt + j) << x0 + (x1 - x0) * i / nx, r * std::cos(t), r * std::sin(t);
    }
  std::vector<Eigen::Vector3i> faces;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nt; ++j) {
      const int a = i * nt + j, b = (i + 1) * nt + j, c = (i + 1) * nt + (j + 1) % nt,
                d = i * nt + (j + 1) % nt;
      faces.emplace_back(a, d, c);
      faces.emplace_back(a, c, b);
    }
  if (capped) {
    const int c0 = (nx + 1) * nt, c1 = c0 + 1;
    m.V.row(c0) << x0, 0, 0;
    m.V.row(c1) << x1, 0, 0;
    for (int j = 0; j < nt; ++j) {
      faces.emplace_back(c0, (j + 1) % nt, j);
      faces.emplace_back(c1, nx * nt + j, nx * nt + (j + 1) % nt);
    }
  }
  m.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) = faces[f];
  return m;
}

// Dist(v, other) for every vertex of V, by exhaustive search with bounding-sphere culling.
inline Eigen::VectorXd distance_to_mesh(const MatrixX3d& V, const TriMesh& other) {
  const Eigen::Index nf = other.F.rows();
  std::vector<Vector3d> a(nf), b(nf), c(nf), center(nf);
  std::vector<double> radius(nf);
  for (Eigen::Index f = 0; f < nf; ++f) {
    a[f] = other.V.row(other.F(f, 0)).transpose();
    b[f] = other.V.row(other.F(f, 1)).transpose();
    c[f] = other.V.row(other.F(f, 2)).transpose();
    center[f] = (a[f] + b[f] + c[f]) / 3.0;
    radius[f] =
        std::max({(a[f] - center[f]).norm(), (b[f] - center[f]).norm(), (c[f] - center[f]).norm()});
  }
  Eigen::VectorXd d(V.rows());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const Vector3d p = V.row(v).transpose();
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = 0; f < nf; ++f) {
      const double lower = std::max(0.0, (p - center[f]).norm() - radius[f]);
      if (lower * lower >= best) continue;
      best = std::min(best, point_triangle_squared_distance<double>(p, a[f], b[f], c[f]));
    }
    d(v) = std::sqrt(best);
  }
  return d;
}

inline Vector3d face_centroid(const TriMesh& m, int f) {
  return (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1)) + m.V.row(m.F(f, 2))).transpose() / 3.0;
}

// Per directed edge (a, b), how many faces traverse it.
inline std::map<std::pair<int, int>, int> directed_edge_counts(const MatrixX3i& F) {
  std::map<std::pair<int, int>, int> count;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++count[{F(f, k), F(f, (k + 1) % 3)}];
  return count;
}

}  // namespace mq::test
