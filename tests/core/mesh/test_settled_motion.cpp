#include <gtest/gtest.h>

#include <vector>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/settled_motion.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// Two cubes side by side: a unit cube (12 faces) at the origin and, 0.5 to its right, a unit
// cube of more faces (each face split into 4 triangles by its centre: 24 faces).
TriMesh two_cubes() {
  TriMesh small = test::unit_cube(), large = test::unit_cube();
  // The large cube's faces split at their centroids: same box, more faces.
  TriMesh split;
  split.V = large.V;
  std::vector<Eigen::RowVector3i> faces;
  for (int f = 0; f < large.num_faces(); ++f) {
    const int a = large.F(f, 0), b = large.F(f, 1), c = large.F(f, 2);
    const int m = static_cast<int>(split.V.rows());
    split.V.conservativeResize(m + 1, 3);
    split.V.row(m) = (large.V.row(a) + large.V.row(b) + large.V.row(c)) / 3;
    faces.emplace_back(a, b, m);
    faces.emplace_back(b, c, m);
    faces.emplace_back(c, a, m);
  }
  split.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t i = 0; i < faces.size(); ++i) split.F.row(static_cast<Eigen::Index>(i)) = faces[i];
  split.V.col(0).array() += 1.5;
  TriMesh out = small;
  const int n = static_cast<int>(out.V.rows());
  out.V.conservativeResize(n + split.V.rows(), 3);
  out.V.bottomRows(split.V.rows()) = split.V;
  out.F.conservativeResize(small.F.rows() + split.F.rows(), 3);
  out.F.bottomRows(split.F.rows()) = split.F.array() + n;
  return out;
}

// Frames moving the first `moving` vertices (the small cube) and, with `both`, the large one back
// towards it by reach[k] times the amplitude.
FramePositions towards(const TriMesh& m, int moving, const std::vector<double>& reach, bool both) {
  return [&m, moving, reach, both](int k, const std::vector<double>& a) {
    MatrixX3d V = m.V;
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
      const bool small = v < moving;
      if (!small && !both) continue;
      const double s = a[small ? 0 : 1] * reach[static_cast<size_t>(k)];
      if (s != 0) V(v, 0) += small ? s : -s;
    }
    return V;
  };
}

TEST(SettledMotion, TheSmallerElementIsDampedThenStilled) {
  const TriMesh m = two_cubes();
  SettledMotionStats s;
  // The small cube moves 0.2 then 0.8 to the right: at 0.8 it meets the large one, at half of it
  // (0.4) it stays clear.
  EXPECT_EQ(settled_amplitudes(m.V, m.F, 2, towards(m, 8, {0.2, 0.8}, false), &s),
            (std::vector<double>{0.5, 1.0}));
  EXPECT_EQ(s.damped, 1);
  EXPECT_EQ(s.stilled, 0);
  // At 2.0, half (1.0) still meets it: it stays still; the large cube, not moving, is kept.
  EXPECT_EQ(settled_amplitudes(m.V, m.F, 1, towards(m, 8, {2.0}, false), &s),
            (std::vector<double>{0.0, 1.0}));
  EXPECT_EQ(s.stilled, 1);
  // Both moving towards each other by 0.3: the small one damped to 0.15 leaves 0.05 between them.
  EXPECT_EQ(settled_amplitudes(m.V, m.F, 1, towards(m, 8, {0.3}, true), &s),
            (std::vector<double>{0.5, 1.0}));
  // By 1.0 each: the small one stills, then the large one (moving into a still cube) halves, and
  // at 0.5 it touches the still cube (touching counts), so it stills too.
  EXPECT_EQ(settled_amplitudes(m.V, m.F, 1, towards(m, 8, {1.0}, true), &s),
            (std::vector<double>{0.0, 0.0}));
  // Motion that meets nothing is kept whole.
  EXPECT_EQ(settled_amplitudes(m.V, m.F, 2, towards(m, 8, {-1.0, 0.3}, false), &s),
            (std::vector<double>{1.0, 1.0}));
  EXPECT_EQ(s.damped + s.stilled, 0);
}

}  // namespace
}  // namespace mq
