// Fixtures shared by the shell-space tests: an icosphere and real bases offset by 2% of their
// bounding-box diagonal.
#pragma once

#include <map>
#include <utility>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"
#include "core/shell/offset_surface.h"
#include "tests/test_support.h"

namespace mq::test {

// The same piecewise-flat surface with four times the faces: each face split at its edge
// midpoints; vertices 0..#V-1 are kept in place and order.
inline TriMesh midpoint_split(const TriMesh& m) {
  std::map<std::pair<int, int>, int> mid;
  std::vector<Vector3d> V;
  for (int i = 0; i < m.V.rows(); ++i) V.push_back(m.V.row(i));
  auto midpoint = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    V.push_back(0.5 * (V[a] + V[b]));
    return mid[key] = static_cast<int>(V.size()) - 1;
  };
  TriMesh out;
  out.F.resize(4 * m.F.rows(), 3);
  for (int f = 0; f < m.F.rows(); ++f) {
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << b, bc, ab;
    out.F.row(4 * f + 2) << c, ca, bc;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  out.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (std::size_t i = 0; i < V.size(); ++i) out.V.row(static_cast<Eigen::Index>(i)) = V[i];
  return out;
}

// Unit icosphere (closed, convex, counter-clockwise outward), subdivided `levels` times.
inline TriMesh icosphere(int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriMesh m;
  m.V.resize(12, 3);
  m.V << -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0, 0, -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, t, 0, -1,
      t, 0, 1, -t, 0, -1, -t, 0, 1;
  m.F.resize(20, 3);
  m.F << 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7,
      1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8,
      1;
  for (int l = 0; l < levels; ++l) m = midpoint_split(m);
  for (int i = 0; i < m.V.rows(); ++i) m.V.row(i).normalize();
  return m;
}

inline double bbox_diagonal(const TriMesh& m) { return bounding_box(m.V, m.F).extent().norm(); }

// The real base `name` and its offset surface at 2% of the bounding-box diagonal.
struct OffsetBase {
  TriMesh base;
  OffsetOptions options;
  OffsetSurface offset;
};
inline OffsetBase offset_base(const std::string& name) {
  OffsetBase ob;
  ob.base = read_mesh(shared_data(name));
  ob.options.height = 0.02 * bbox_diagonal(ob.base);
  ob.offset = offset_surface(ob.base.V, ob.base.F, ob.options);
  return ob;
}

}  // namespace mq::test
