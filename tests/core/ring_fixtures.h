// Rings in the shapes a map can give them, for the structure measure's tests: squeezed (a tube
// around an ellipse or a stadium), bent over a rounded right-angled edge into a C, or bent over a
// cylinder. Every fixture is a closed genus-1 tube of constant wire radius.
#pragma once

#include <cmath>
#include <functional>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq::test {

// A closed tube of radius r around the closed planar curve C(t), t in [0, 2 pi), in the z = 0
// plane, n sections of m vertices (the section in the plane spanned by the curve's in-plane normal
// and z), faces outward for a counter-clockwise curve.
inline TriMesh planar_tube(const std::function<Vector2d(double)>& C, double r, int n, int m) {
  TriMesh t;
  t.V.resize(n * m, 3);
  t.F.resize(2 * n * m, 3);
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n, h = 1e-6;
    const Vector2d p = C(a), d = (C(a + h) - C(a - h)).normalized();
    const Vector3d side(d.y(), -d.x(), 0);  // outward for a counter-clockwise curve
    for (int j = 0; j < m; ++j) {
      const double phi = 2 * M_PI * j / m;
      t.V.row(k * m + j) = Vector3d(p.x(), p.y(), 0) +
                           r * (std::cos(phi) * side + std::sin(phi) * Vector3d::UnitZ());
    }
  }
  int f = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < m; ++j) {
      const int k1 = (k + 1) % n, j1 = (j + 1) % m;
      const int a = k * m + j, b = k * m + j1, c = k1 * m + j1, d = k1 * m + j;
      t.F.row(f++) << a, b, c;
      t.F.row(f++) << a, c, d;
    }
  return t;
}

// A ring of centre radius 1 squeezed along y: its centre curve the ellipse with semi-axes 1 and b.
inline TriMesh ellipse_ring(double b, double r, int n = 64, int m = 12) {
  return planar_tube([b](double t) { return Vector2d(std::cos(t), b * std::sin(t)); }, r, n, m);
}

// A ring squeezed flat: a stadium (two half circles of radius rho joined by straight sides of
// length 2 - 2 rho along x), as a ring of centre radius 1 pressed until its sides are 2 rho apart.
inline TriMesh stadium_ring(double rho, double r, int n = 64, int m = 12) {
  const double half = 1 - rho;  // half the straight length
  const double perimeter = 4 * half + 2 * M_PI * rho;
  return planar_tube(
      [=](double t) {
        // Arc-length parameter from the right half circle's middle, counter-clockwise.
        double s = t / (2 * M_PI) * perimeter;
        const double arc = M_PI * rho;
        auto around = [&](double cx, double a0, double ds) {
          const double a = a0 + ds / rho;
          return Vector2d(cx + rho * std::cos(a), rho * std::sin(a));
        };
        if (s < arc / 2) return around(half, 0, s);
        s -= arc / 2;
        if (s < 2 * half) return Vector2d(half - s, rho);
        s -= 2 * half;
        if (s < arc) return around(-half, M_PI / 2, s);
        s -= arc;
        if (s < 2 * half) return Vector2d(-half + s, -rho);
        s -= 2 * half;
        return around(half, -M_PI / 2, s);
      },
      r, n, m);
}

// The plane z = 0 (x <= 0) bent down over a rounded edge of radius rho at x = 0 into the wall
// x = rho: points at height z above the plane keep that height above the bent surface.
inline Vector3d over_edge(const Vector3d& p, double rho) {
  const double x = p.x(), y = p.y(), z = p.z();
  if (x <= 0) return p;
  const double arc = M_PI / 2 * rho;
  if (x < arc) {
    const double a = x / rho;
    return Vector3d((rho + z) * std::sin(a), y, (rho + z) * std::cos(a) - rho);
  }
  return Vector3d(rho + z, y, -rho - (x - arc));
}

// The plane z = 0 wrapped onto a cylinder of radius rho along y, tangent to the plane at x = 0.
inline Vector3d over_cylinder(const Vector3d& p, double rho) {
  const double a = p.x() / rho;
  return Vector3d((rho + p.z()) * std::sin(a), p.y(), (rho + p.z()) * std::cos(a) - rho);
}

inline TriMesh mapped(TriMesh m, const std::function<Vector3d(const Vector3d&)>& f) {
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = f(m.V.row(v).transpose());
  return m;
}

}  // namespace mq::test
