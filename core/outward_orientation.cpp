#include "core/outward_orientation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "core/geometry_measures.h"
#include "core/mesh_topology.h"

namespace mq {
namespace {

constexpr int kVoters = 16;

// Distance along the ray o + t d (t > t_min) to triangle abc, or -1 (Moller-Trumbore).
double ray_triangle(const Vector3d& o, const Vector3d& d, const Vector3d& a, const Vector3d& b,
                    const Vector3d& c, double t_min) {
  const Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return -1;
  const double inv = 1 / det;
  const Vector3d s = o - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return -1;
  const Vector3d q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0 || u + v > 1) return -1;
  const double t = e2.dot(q) * inv;
  return t > t_min ? t : -1;
}

}  // namespace

int orient_outward(TriMesh& mesh) {
  std::vector<int> fc;
  const int n = connected_components(mesh.F, mesh.num_vertices(), fc);
  const std::vector<std::vector<int>> groups = component_faces(fc, n);
  const double diagonal = bounding_box(mesh.V, mesh.F).extent().norm();
  const Eigen::VectorXd area = face_areas(mesh.V, mesh.F);
  std::vector<char> flip(static_cast<size_t>(n), 0);
  tbb::parallel_for(0, n, [&](int c) {
    const std::vector<int>& faces = groups[static_cast<size_t>(c)];
    std::vector<int> voters(faces);
    const size_t k = std::min<size_t>(kVoters, voters.size());
    std::partial_sort(voters.begin(), voters.begin() + static_cast<long>(k), voters.end(),
                      [&](int a, int b) { return area(a) > area(b) || (area(a) == area(b) && a < b); });
    int inward = 0, outward = 0;
    for (size_t i = 0; i < k; ++i) {
      const int f = voters[i];
      const Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                     cc = mesh.V.row(mesh.F(f, 2));
      Vector3d d = (b - a).cross(cc - a);
      if (!(d.norm() > 0)) continue;
      d.normalize();
      // Slightly tilted off the normal, so that a ray along a box's axis does not run exactly
      // through the edges of the faces it crosses.
      d = (d + Vector3d(0.0123, 0.0271, 0.0089)).normalized();
      const Vector3d o = (a + b + cc) / 3;
      int crossings = 0;
      for (const int g : faces) {
        if (g == f) continue;
        crossings += ray_triangle(o, d, mesh.V.row(mesh.F(g, 0)), mesh.V.row(mesh.F(g, 1)),
                                  mesh.V.row(mesh.F(g, 2)), 1e-9 * diagonal) > 0;
      }
      ++(crossings % 2 ? inward : outward);
    }
    flip[static_cast<size_t>(c)] = inward > outward;
  });
  int flipped = 0;
  for (int c = 0; c < n; ++c) {
    if (!flip[static_cast<size_t>(c)]) continue;
    ++flipped;
    for (const int f : groups[static_cast<size_t>(c)]) std::swap(mesh.F(f, 1), mesh.F(f, 2));
  }
  return flipped;
}

}  // namespace mq
