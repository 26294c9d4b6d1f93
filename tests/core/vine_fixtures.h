// Fixtures shared by the vine and thread tests: the bench jobs' ivy and a region of a refined
// base given by a predicate on its faces' centroids (SurfaceQuiltingOptions::region).
#pragma once

#include <functional>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/planar/swatch_generators.h"

namespace mq::test {

// The sample ivy of the bench jobs (`swatch ivy --count 2 --length 2`): one vine, two leaves.
inline TriMesh ivy_swatch() {
  IvyOptions o;
  o.leaves = 2;
  o.length = 2;
  return ivy_section(o);
}

// A region for SurfaceQuiltingOptions::region: the faces whose centroid satisfies `inside`.
inline std::function<std::vector<char>(const TriMesh&)> centroid_region(
    const std::function<bool(const Vector3d&)>& inside) {
  return [inside](const TriMesh& refined) {
    std::vector<char> in(static_cast<size_t>(refined.num_faces()));
    for (int f = 0; f < refined.num_faces(); ++f)
      in[static_cast<size_t>(f)] =
          inside((refined.V.row(refined.F(f, 0)) + refined.V.row(refined.F(f, 1)) +
                  refined.V.row(refined.F(f, 2)))
                     .transpose() /
                 3.0);
    return in;
  };
}

}  // namespace mq::test
