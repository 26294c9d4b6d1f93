#include "core/shell/linked_versions.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <optional>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/linking_number.h"
#include "core/shell/element_grid.h"

namespace mq {

void LinkedVersionOptions::validate() const {
  MQ_CHECK(max_fold > 0 && max_fold <= M_PI, InvalidInput,
           "linked versions: max_fold must be in (0, pi], got ", max_fold);
  MQ_CHECK(max_growth >= 1 && max_shrinkage >= 1, InvalidInput,
           "linked versions: max_growth and max_shrinkage must be >= 1, got ", max_growth, " and ",
           max_shrinkage);
  MQ_CHECK(passes >= 0, InvalidInput, "linked versions: passes must be >= 0, got ", passes);
}

namespace {

double loop_length(const Loop& loop) {
  double length = 0;
  for (size_t i = 0; i < loop.size(); ++i) length += (loop[(i + 1) % loop.size()] - loop[i]).norm();
  return length;
}

// Would the structure measure take P as a ring: hole open (at least its wire across), folded no
// more than the flat element's own fold plus max_fold?
bool sound_ring(const MatrixX3d& P, const SurfaceElement& e, const Loop& loop, double max_fold) {
  const RingShape shape = ring_shape(P, e.F, loop);
  if (!(shape.opening >= shape.wire)) return false;
  double reference = 0;  // a ring made bent stays as bent
  if (e.flat.rows() == P.rows())
    if (const std::optional<Loop> flat = ring_centre_loop(e.flat, e.F))
      reference = ring_shape(e.flat, e.F, *flat).fold;
  return shape.fold - reference <= max_fold;
}

BoundingBox box_of_loop(const Loop& loop) {
  BoundingBox b;
  for (const Vector3d& p : loop) b.extend(p);
  return b;
}

// How many of the rings near k (within `box`, by the grid) `loop` links. Two loops whose boxes
// are apart cannot link (a plane parts them): only loops whose boxes meet are tested.
int links_of(const Loop& loop, size_t k, const BoundingBox& box, const ElementGrid& grid,
             const std::vector<std::optional<Loop>>& loops) {
  const BoundingBox own = box_of_loop(loop);
  int links = 0;
  for (const int j : grid.near(box)) {
    const std::optional<Loop>& other = loops[static_cast<size_t>(j)];
    if (static_cast<size_t>(j) != k && other && ElementGrid::overlap(own, box_of_loop(*other)) &&
        linking_number(loop, *other) != 0)
      ++links;
  }
  return links;
}

// The rows of V, A and the offsets of both, as choose_linked_versions takes them.
struct Versions {
  const SurfaceQuilt& quilt;
  const std::vector<Eigen::Index>& first;
  MatrixX3d& V;
  MatrixX3d& A;
  const std::vector<Eigen::Index>& alternative_first;

  MatrixX3d placed(size_t k) const { return V.middleRows(first[k], first[k + 1] - first[k]); }
  MatrixX3d other(size_t k) const {
    return A.middleRows(alternative_first[k], alternative_first[k + 1] - alternative_first[k]);
  }
};

// Each candidate's reach (both versions' box), and the centre loops, as placed, of the elements
// in reach of one (nothing for elements that are not rings): the only loops judged.
void reach_and_loops(const Versions& x, const std::vector<char>& candidate,
                     std::vector<BoundingBox>& reach, std::vector<std::optional<Loop>>& loops) {
  const size_t ne = candidate.size();
  reach.assign(ne, BoundingBox());
  loops.assign(ne, std::nullopt);
  std::vector<char> needed(ne, 0);
  const ElementGrid grid(x.V, x.first, std::vector<char>(ne, 0));
  tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
    if (!candidate[k]) return;
    reach[k] = bounding_box(x.placed(k));
    const BoundingBox other = bounding_box(x.other(k));
    reach[k].extend(other.min);
    reach[k].extend(other.max);
  });
  for (size_t k = 0; k < ne; ++k)
    if (candidate[k]) {
      needed[k] = 1;
      for (const int j : grid.near(reach[k])) needed[static_cast<size_t>(j)] = 1;
    }
  tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
    if (needed[k]) loops[k] = ring_centre_loop(x.placed(k), x.quilt.elements[k].F);
  });
}

// The links candidate k gains by taking its layout version (0: none, or it may not), and that
// version's loop in `taken`.
int judge(const Versions& x, size_t k, const BoundingBox& reach, const ElementGrid& grid,
          const std::vector<std::optional<Loop>>& loops, const LinkedVersionOptions& options,
          std::optional<Loop>& taken) {
  const SurfaceElement& e = x.quilt.elements[k];
  const MatrixX3d layout = x.other(k);
  std::optional<Loop> loop = ring_centre_loop(layout, e.F);
  if (!loop) return 0;
  // The copy has the element's size (clamped as place_linear clamps it).
  const double by_copy_length = loop_length(*loops[k]), length = loop_length(*loop);
  if (!(length <= options.max_growth * by_copy_length &&
        by_copy_length <= options.max_shrinkage * length))
    return 0;
  // The links first (a few dozen loop pairs); the shapes, dearer, only for a ring that could
  // gain: one linked more by the layout's version, or as much where the copy is no sound ring
  // (its links count for nothing then).
  int by_copy = links_of(*loops[k], k, reach, grid, loops);
  const int by_layout = links_of(*loop, k, reach, grid, loops);
  if (by_layout < by_copy || by_layout == 0) return 0;
  if (by_layout == by_copy) {
    if (sound_ring(x.placed(k), e, *loops[k], options.max_fold)) return 0;
    by_copy = 0;
  }
  if (!sound_ring(layout, e, *loop, options.max_fold)) return 0;
  taken = std::move(loop);
  return by_layout - by_copy;
}

}  // namespace

std::vector<char> choose_linked_versions(
    const SurfaceQuilt& quilt, const std::vector<Eigen::Index>& first, MatrixX3d& V, MatrixX3d& A,
    const std::vector<Eigen::Index>& alternative_first, const std::vector<char>& skip,
    const LinkedVersionOptions& options, LinkedVersionStats* stats) {
  options.validate();
  const size_t ne = quilt.elements.size();
  MQ_CHECK(first.size() == ne + 1 && alternative_first.size() == ne + 1 && skip.size() == ne &&
               first.back() == V.rows() && alternative_first.back() == A.rows(),
           InvalidInput, "linked versions: offsets do not fit the elements' rows");
  std::vector<char> swapped(ne, 0), candidate(ne, 0);
  LinkedVersionStats st;
  for (size_t k = 0; k < ne; ++k) {
    const Eigen::Index n = alternative_first[k + 1] - alternative_first[k];
    candidate[k] = !skip[k] && n > 0 && n == first[k + 1] - first[k];
    st.candidates += candidate[k];
  }
  const Versions x{quilt, first, V, A, alternative_first};
  std::vector<BoundingBox> reach;
  std::vector<std::optional<Loop>> loops;
  if (st.candidates > 0) reach_and_loops(x, candidate, reach, loops);
  for (int pass = 0; st.candidates > 0 && pass < options.passes; ++pass) {
    // Every ring judged against the others as they stand at the pass's start.
    const ElementGrid grid(V, first, std::vector<char>(ne, 0));
    std::vector<int> gain(ne, 0);
    std::vector<std::optional<Loop>> taken(ne);
    tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
      if (candidate[k] && !swapped[k] && loops[k])
        gain[k] = judge(x, k, reach[k], grid, loops, options, taken[k]);
    });
    // The next pass judges again only the candidates whose reach meets a swapped ring's (the
    // others' neighbours stand as they were judged).
    ElementGrid moved(V, first, std::vector<char>(ne, 1));
    int changed = 0;
    for (size_t k = 0; k < ne; ++k) {
      if (!taken[k]) continue;
      moved.insert(static_cast<int>(k), reach[k]);
      const Eigen::Index n = first[k + 1] - first[k];
      V.middleRows(first[k], n).swap(A.middleRows(alternative_first[k], n));
      loops[k] = std::move(taken[k]);
      swapped[k] = 1;
      ++st.chosen;
      st.links_gained += gain[k];
      ++changed;
    }
    if (changed == 0) break;
    for (size_t k = 0; k < ne; ++k)
      candidate[k] = candidate[k] && !swapped[k] && !moved.near(reach[k]).empty();
  }
  if (stats) *stats = st;
  return swapped;
}

}  // namespace mq
