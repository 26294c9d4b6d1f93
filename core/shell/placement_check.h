// The embedding's check of its own result (issue 23: no silent wrong result): per output vertex
// its signed height over the base as given (core/shell/signed_height), counted below the base (more
// than a tolerance under it) or above the shell (farther out than the shell height and the
// tolerance). The texture of section 3 lives in the shell between the base and its offset;
// geometry under the base is hidden inside the object.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"
#include "core/shell/signed_height.h"

namespace mq {

struct PlacementCheckOptions {
  double height = 0.0;      // shell height H (> 0)
  double tolerance = 0.01;  // in shell heights (>= 0): below means under -tolerance * H
};

// One element's figures.
//   vertices  its vertices
//   below     vertices more than tolerance * H below the base
//   above     vertices more than (1 + tolerance) * H above it
//   lowest    the lowest signed height among the vertices queried (the first always is); when
//             negative it is the element's lowest, since vertices skipped are above the base
//   queries   closest-point queries made
//   lowest_vertex  the row of V where `lowest` was found (-1 for an unchecked element)
struct ElementHeights {
  int vertices = 0, below = 0, above = 0, queries = 0;
  double lowest = 0.0;
  Eigen::Index lowest_vertex = -1;
};

// Checks every element k with check[k] set (all when `check` is empty), its vertices the rows
// [first[k], first[k + 1]) of V. A vertex closer to an already measured vertex a (above the
// base at height s) than s is joined to it by a segment that cannot meet the base, so it lies
// above the base too, at a distance within s +- their distance: it needs no query of its own
// when that distance also keeps it inside the shell (on the armor job 17% of the vertices are
// queried). TBB over elements, each walked in vertex order: the figures do not depend on the
// thread count.
//   V #V by 3, first #elements + 1 ascending offsets ending at #V, check empty or #elements
// Returns #elements figures (zero for unchecked elements). Throws InvalidInput for bad options,
// offsets or non-finite vertices.
std::vector<ElementHeights> check_element_heights(const SignedHeight& base, const MatrixX3d& V,
                                                  const std::vector<Eigen::Index>& first,
                                                  const PlacementCheckOptions& options,
                                                  const std::vector<char>& check = {});

// Moves each element k with lift[k] set that lies under the base out of it, whole: translated
// along the way from its lowest vertex up to that vertex's closest point on the base, by that
// distance and half the tolerance, up to `steps` times (another part of it may then be the
// lowest). For elements the repairs after embedding pushed into the base (a folded element's
// flat shape fitted over a curved base, a ring moved away from its neighbours): a rigid lift
// keeps them whole where removing them would leave a hole. Writes the moved rows of V and
// returns the figures after (zero for elements not lifted); moved[k] (if given, #elements)
// tells which moved. Throws as check_element_heights, and InvalidInput for steps < 1.
std::vector<ElementHeights> lift_out_of_base(const SignedHeight& base, MatrixX3d& V,
                                             const std::vector<Eigen::Index>& first,
                                             const PlacementCheckOptions& options,
                                             const std::vector<char>& lift, int steps = 4,
                                             std::vector<char>* moved = nullptr);

// Totals over the elements with keep[k] set (all when `keep` is empty).
struct PlacementFigures {
  long long vertices = 0, below = 0, above = 0;
  double lowest = 0.0;  // lowest signed height found (0 when none is negative)
  double below_share() const { return vertices ? static_cast<double>(below) / vertices : 0.0; }
  double above_share() const { return vertices ? static_cast<double>(above) / vertices : 0.0; }
};
// keep: empty or as many flags as heights (missing flags count as set). Throws nothing.
PlacementFigures placement_figures(const std::vector<ElementHeights>& heights,
                                   const std::vector<char>& keep = {});

}  // namespace mq
