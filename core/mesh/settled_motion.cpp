#include "core/mesh/settled_motion.h"

#include <algorithm>
#include <set>
#include <utility>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

std::vector<char> moved_faces(const MatrixX3d& rest, const MatrixX3d& V, const MatrixX3i& F) {
  std::vector<char> moved(static_cast<size_t>(F.rows()), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    moved[static_cast<size_t>(f)] = V.row(F(f, 0)) != rest.row(F(f, 0)) ||
                                    V.row(F(f, 1)) != rest.row(F(f, 1)) ||
                                    V.row(F(f, 2)) != rest.row(F(f, 2));
  return moved;
}

std::vector<double> settled_amplitudes(const MatrixX3d& rest, const MatrixX3i& F, int frames,
                                       const FramePositions& positions, SettledMotionStats* stats) {
  std::vector<int> label;
  const int elements = connected_components(F, static_cast<int>(rest.rows()), label);
  std::vector<double> amplitude(static_cast<size_t>(elements), 1.0);
  std::vector<int> faces(static_cast<size_t>(elements), 0);
  for (const int e : label) ++faces[static_cast<size_t>(e)];
  IntersectionOptions all;
  all.between_components_only = false;
  // What rest already has is not the motion's doing.
  const auto at_rest = intersecting_face_pairs(rest, F, all);
  const std::set<std::pair<int, int>> known(at_rest.begin(), at_rest.end());
  std::vector<char> active(static_cast<size_t>(F.rows()), 1);
  SettledMotionStats s;
  for (bool first = true;; first = false) {
    ++s.rounds;
    std::vector<char> meets(static_cast<size_t>(elements), 0);
    // Of two elements that meet, the smaller is damped (a leaf, not the stem that carries it and
    // its other leaves); both when alike in size, the larger once the smaller is still.
    const auto mark = [&](int a, int b) {
      const int fa = faces[static_cast<size_t>(a)], fb = faces[static_cast<size_t>(b)];
      const bool still_a = amplitude[static_cast<size_t>(a)] == 0,
                 still_b = amplitude[static_cast<size_t>(b)] == 0;
      if (a == b || fa == fb || (fa < fb ? still_a : still_b)) {
        meets[static_cast<size_t>(a)] = meets[static_cast<size_t>(b)] = 1;
      } else {
        meets[static_cast<size_t>(fa < fb ? a : b)] = 1;
      }
    };
    for (int k = 0; k < frames; ++k) {
      const MatrixX3d V = positions(k, amplitude);
      // At first the faces that move in this frame (pairs of faces at rest are rest's), then
      // those of the elements just damped.
      const std::vector<char> tested = first ? moved_faces(rest, V, F) : active;
      if (std::find(tested.begin(), tested.end(), 1) == tested.end()) continue;
      const auto pairs = intersecting_face_pairs_touching(V, F, tested);
      for (const auto& pair : pairs)
        if (!known.count(pair))
          mark(label[static_cast<size_t>(pair.first)], label[static_cast<size_t>(pair.second)]);
    }
    bool changed = false;
    for (int e = 0; e < elements; ++e)
      if (meets[static_cast<size_t>(e)] && amplitude[static_cast<size_t>(e)] > 0) {
        double& a = amplitude[static_cast<size_t>(e)];
        a = a == 1.0 ? 0.5 : 0.0;
        changed = true;
      } else {
        meets[static_cast<size_t>(e)] = 0;
      }
    if (!changed) break;
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      active[static_cast<size_t>(f)] = meets[static_cast<size_t>(label[static_cast<size_t>(f)])];
  }
  s.damped = static_cast<int>(std::count(amplitude.begin(), amplitude.end(), 0.5));
  s.stilled = static_cast<int>(std::count(amplitude.begin(), amplitude.end(), 0.0));
  if (stats) *stats = s;
  return amplitude;
}

}  // namespace mq
