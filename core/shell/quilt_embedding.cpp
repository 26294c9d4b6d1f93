#include "core/shell/quilt_embedding.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/shell/element_grid.h"
#include "core/shell/element_removal.h"
#include "core/shell/element_unfolding.h"
#include "core/shell/linked_versions.h"
#include "core/shell/offset_surface.h"
#include "core/shell/placement_check.h"
#include "core/shell/quilt_intersections.h"
#include "core/shell/ring_separation.h"
#include "core/shell/ring_unbending.h"
#include "core/shell/shell_embedding.h"
#include "core/shell/shell_map.h"
#include "core/shell/signed_height.h"
#include "core/shell/surface_coverage.h"

namespace mq {

namespace {

// #elements + 1 offsets of each element's vertices in the embedding's one matrix.
std::vector<Eigen::Index> vertex_offsets(const SurfaceQuilt& quilt) {
  std::vector<Eigen::Index> first(quilt.elements.size() + 1, 0);
  for (size_t k = 0; k < quilt.elements.size(); ++k)
    first[k + 1] = first[k] + static_cast<Eigen::Index>(quilt.elements[k].face.size());
  return first;
}

// Rings that separation took farther from the base than the shell (or than they already were,
// where the map left them farther), or under the base as given (deeper than the check allows
// and than they already were), are put back: the texture stays in its shell. Distances from
// every vertex of a moved ring (exact closest points on the base; signed heights through
// check_element_heights). Restores those rings' rows of V from `before` and clears their
// `moved` flags; returns how many.
int keep_in_shell(const SurfaceQuilt& quilt, const std::vector<Eigen::Index>& first,
                  const MatrixX3d& before, MatrixX3d& V, std::vector<char>& moved,
                  const SignedHeight& heights, const PlacementCheckOptions& check) {
  if (std::find(moved.begin(), moved.end(), 1) == moved.end()) return 0;
  const ClosestPointQuery base(quilt.input_base.V, quilt.input_base.F);
  const auto farthest = [&](const MatrixX3d& X, size_t k, double within) {
    double d = 0;
    for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) {
      const ClosestPointHit hit = base.closest(Vector3d(X.row(v).transpose()), within);
      if (hit.face < 0) return std::numeric_limits<double>::infinity();
      d = std::max(d, hit.distance);
    }
    return d;
  };
  const std::vector<ElementHeights> was =
      check_element_heights(heights, before, first, check, moved);
  const std::vector<ElementHeights> is = check_element_heights(heights, V, first, check, moved);
  std::vector<char> back(moved.size(), 0);
  tbb::parallel_for(size_t{0}, moved.size(), [&](size_t k) {
    if (!moved[k]) return;
    if (is[k].below > 0 && is[k].lowest < was[k].lowest) {
      back[k] = 1;
      return;
    }
    const double limit =
        std::max(quilt.shell_height, farthest(before, k, std::numeric_limits<double>::infinity()));
    back[k] = farthest(V, k, limit) > limit;
  });
  int count = 0;
  for (size_t k = 0; k < moved.size(); ++k)
    if (back[k]) {
      V.middleRows(first[k], first[k + 1] - first[k]) =
          before.middleRows(first[k], first[k + 1] - first[k]);
      moved[k] = 0;
      ++count;
    }
  return count;
}

// The embedding's state between its steps: every element's vertices in one matrix (element k's
// rows [first[k], first[k + 1])), their local coordinates, and what the steps learn about each
// element (placed by normal displacement, under the base, moved since last checked, dropped).
class QuiltEmbedder {
 public:
  QuiltEmbedder(const SurfaceQuilt& quilt, const QuiltEmbeddingOptions& options,
                QuiltEmbeddingStats& stats, ProgressSink* progress);
  bool empty() const { return first_.back() == 0; }  // no vertex to embed
  void build_shell_map();
  void embed(TetStretchEvaluator& stretch);
  void embed_layout_versions();
  void choose_linked_versions();
  void check_placement();
  void repair_folds();
  std::vector<char> unbend_folded_rings(const std::vector<char>& absent,
                                        RingUnbendingStats& unbending,
                                        const std::vector<char>* candidates = nullptr);
  std::vector<char> separate_touching_rings(const std::vector<char>* absent = nullptr);
  void remove_intersecting();
  void unbend_kept_folds();
  // Per element: dropped or sunk (out of the output, no neighbour of any repair).
  std::vector<char> absent_elements() const;
  void check_output();
  TriMesh output();
  void measure_coverage(const TriMesh& out);

 private:
  void embed_through_map(TetStretchEvaluator& stretch);
  const MatrixX3d& shell_directions();
  void place_by_normal(const std::vector<char>& which);
  std::vector<char> lift_moved();
  void forget_sunk(std::vector<std::pair<int, int>>& p) const;
  void find_pairs_once();
  void update_pairs(const std::vector<char>& moved);

  const SurfaceQuilt& quilt_;
  const QuiltEmbeddingOptions& options_;
  QuiltEmbeddingStats& stats_;
  ProgressSink* progress_;
  size_t ne_;
  std::vector<Eigen::Index> first_;
  LocalCoordinates points_;      // heights clamped into the shell
  TriMesh all_;                  // every element, in order
  std::vector<int> element_of_;  // #F(all_)
  std::unique_ptr<ShellMap> map_;
  std::vector<char> by_normal_;  // placed by normal displacement (no shell under it)
  LocalCoordinates mapped_;      // points_ in the map's face numbering
  bool known_disjoint_ = false;  // no two elements of all_.V intersect (already checked)
  // The intersecting face pairs of all_.V (within an element and between two), once found kept
  // up to date as elements move (updated_face_pairs): one full pass instead of three.
  std::vector<std::pair<int, int>> pairs_;
  bool have_pairs_ = false;
  std::vector<char> stale_;     // moved since pairs_ was found (their pairs out of date)
  std::vector<char> restored_;  // dropped, then brought back by the removal (pairs not updated)
  // Since the fold repair's unbending: which elements were absent then (dropped or sunk), and
  // which moved after it; a folded ring none of whose neighbours changed is unbent (or not)
  // the same way again.
  std::vector<char> absent_at_unbending_;
  std::vector<char> moved_since_unbending_;
  // The layout's versions of elements placed as even copies (SurfaceElement::through_layout).
  std::vector<Eigen::Index> alternative_first_;
  MatrixX3d alternative_V_;
  std::vector<char> alternative_by_normal_;  // per element: its layout version so placed
  PlacementCheckOptions check_;
  std::optional<SignedHeight> base_height_;
  std::vector<ElementHeights> heights_;
  std::vector<char> sunk_;               // still under the base after the fallback: removed
  std::vector<char> moved_after_check_;  // moved by a repair since checked: checked again
  std::vector<char> drop_, folded_;
  std::optional<MatrixX3d> directions_;  // shell_directions(), made once when first needed
};

QuiltEmbedder::QuiltEmbedder(const SurfaceQuilt& quilt, const QuiltEmbeddingOptions& options,
                             QuiltEmbeddingStats& stats, ProgressSink* progress)
    : quilt_(quilt),
      options_(options),
      stats_(stats),
      progress_(progress),
      ne_(quilt.elements.size()),
      first_(vertex_offsets(quilt)) {
  const Eigen::Index nv = first_.back();
  Eigen::Index nf = 0;
  for (const SurfaceElement& e : quilt.elements) nf += e.F.rows();
  points_.face.resize(nv);
  points_.bary.resize(nv, 3);
  points_.height.resize(nv);
  all_.F.resize(nf, 3);
  element_of_.resize(static_cast<size_t>(nf));
  nf = 0;
  for (size_t k = 0; k < ne_; ++k) {
    const SurfaceElement& e = quilt.elements[k];
    const Eigen::Index v0 = first_[k];
    for (size_t v = 0; v < e.face.size(); ++v) {
      points_.face(v0 + v) = e.face[v];
      points_.bary.row(v0 + v) = e.barycentric.row(v);
      points_.height(v0 + v) = std::clamp(e.height(v), 0.0, quilt.shell_height);
    }
    all_.F.middleRows(nf, e.F.rows()) = e.F.array() + static_cast<int>(v0);
    std::fill(element_of_.begin() + nf, element_of_.begin() + nf + e.F.rows(), static_cast<int>(k));
    nf += e.F.rows();
  }
  by_normal_.assign(ne_, 1);
  stale_.assign(ne_, 0);
  restored_.assign(ne_, 0);
  absent_at_unbending_.assign(ne_, 0);
  moved_since_unbending_.assign(ne_, 0);
  sunk_.assign(ne_, 0);
  moved_after_check_.assign(ne_, 0);
  drop_.assign(ne_, 0);
  folded_.assign(ne_, 0);
  check_.height = quilt.shell_height;
  check_.tolerance = stats.placement_tolerance;
}

// The directions normal displacement follows, over the refined base: the shell's smoothed
// offset directions (core/shell/offset_surface). Its plain vertex normals fan out at a spike's tip
// (rings there pressed into each other: 72 removed on the spiky sphere against 20), and those of
// a coarse base as given shear a box's faces (a corner's is 55 degrees off each). Made once: the
// embedding, the layout's versions and both fallbacks use them.
const MatrixX3d& QuiltEmbedder::shell_directions() {
  if (!directions_)
    directions_ = displacement_directions(quilt_.base.V, quilt_.base.F, quilt_.shell_height);
  return *directions_;
}

// The rows of the elements with which[k] set placed by normal displacement (the fallback where
// the shell map is not built, or where it put an element under the base).
void QuiltEmbedder::place_by_normal(const std::vector<char>& which) {
  std::vector<Eigen::Index> rows;
  for (size_t k = 0; k < ne_; ++k)
    if (which[k])
      for (Eigen::Index v = first_[k]; v < first_[k + 1]; ++v) rows.push_back(v);
  if (rows.empty()) return;
  LocalCoordinates sub;
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  sub.face.resize(n);
  sub.bary.resize(n, 3);
  sub.height.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    sub.face(i) = points_.face(rows[static_cast<size_t>(i)]);
    sub.bary.row(i) = points_.bary.row(rows[static_cast<size_t>(i)]);
    sub.height(i) = points_.height(rows[static_cast<size_t>(i)]);
  }
  const MatrixX3d placed =
      normal_displacement(quilt_.base.V, quilt_.base.F, shell_directions(), sub);
  for (Eigen::Index i = 0; i < n; ++i) all_.V.row(rows[static_cast<size_t>(i)]) = placed.row(i);
}

// The stretch-minimised shell map (section 3.2) over the refined base, whose faces are no
// larger than a third of the swatch: over the base as given, a coarse model's large faces
// interpolate its corners' offset directions (a box corner's is 55 degrees off each face), and
// the shell over a whole face is sheared and thinner (a cube's by 1/sqrt(3)): rings lay
// flattened and slanted on Blender's cube (median aspect 1.33 against 1.05 over the refined
// cube). Where no valid shell exists at all, the texture is still placed, by normal
// displacement, and the reason is reported.
void QuiltEmbedder::build_shell_map() {
  ShellMapOptions map_options;
  map_options.height = quilt_.shell_height;
  ScopedStage stage(stats_.times, progress_, Stage::ShellMap);
  try {
    map_ = std::make_unique<ShellMap>(quilt_.base.V, quilt_.base.F, map_options);
    stats_.atlas_charts = map_->atlas().num_charts;
    stats_.shell_smoothing_steps = map_->offset().smoothing_steps;
    stats_.fold_repaired_vertices = static_cast<int>(map_->fold_repair().moved_vertices.size());
    const ShellExclusion& left_out = map_->exclusion();
    stats_.fallback_faces = static_cast<int>(left_out.faces.size());
    stats_.fallback_area_share = left_out.area_share;
    stats_.fallback_fold_faces = left_out.fold_faces;
    stats_.fallback_reason = left_out.reason;
  } catch (const TopologyError& e) {
    stats_.shell_map_failure = e.what();
    stats_.fallback_faces = quilt_.base.num_faces();
    stats_.fallback_area_share = 1;
    stats_.fallback_reason = e.what();
  }
  if (!map_) return;
  // Elements with a vertex over a face the map left out are placed whole by normal
  // displacement (per-region fallback); the others through the map, in its face numbering.
  std::fill(by_normal_.begin(), by_normal_.end(), 0);
  mapped_ = points_;
  for (size_t k = 0; k < ne_; ++k)
    for (Eigen::Index v = first_[k]; v < first_[k + 1]; ++v)
      if (map_->shell_face(points_.face(v)) < 0) by_normal_[k] = 1;
  for (size_t k = 0; k < ne_; ++k)
    for (Eigen::Index v = first_[k]; v < first_[k + 1]; ++v)
      mapped_.face(v) = by_normal_[k] ? 0 : map_->shell_face(points_.face(v));
  stats_.fallback_elements = static_cast<int>(std::count(by_normal_.begin(), by_normal_.end(), 1));
}

// Every element placed in 3D: through the shell map where it has one, else by normal
// displacement along the shell's smoothed offset directions.
void QuiltEmbedder::embed(TetStretchEvaluator& stretch) {
  if (map_) {
    embed_through_map(stretch);
    return;
  }
  ScopedStage stage(stats_.times, progress_, Stage::Embedding);
  all_.V = normal_displacement(quilt_.base.V, quilt_.base.F, shell_directions(), points_);
}

// The unoptimised map creates no intersections where the base is concave (the shell is valid
// and elements lie in it apart); the optimised one bends its tetrahedra a little, and an element
// whose triangles span a bent tetrahedron boundary can then touch a neighbour (chain mail over
// the knight: 8 face pairs of 2 rings, none without optimisation). Those elements, and those
// the optimised map folds through themselves, keep the unoptimised map.
void QuiltEmbedder::embed_through_map(TetStretchEvaluator& stretch) {
  MatrixX3d unoptimized;
  if (options_.optimize_stretch) {
    ScopedStage stage(stats_.times, progress_, Stage::Embedding);
    unoptimized = ShellEmbedding(*map_).embed(mapped_);
  }
  {
    ScopedStage stage(stats_.times, progress_, Stage::StretchOptimization);
    stats_.stretch_before = stats_.stretch_after = map_->stretch(stretch);
    if (options_.optimize_stretch) {
      ShellOptimizeOptions o;
      o.seed = options_.seed;
      const ShellOptimizeReport report = map_->optimize(stretch, o);
      stats_.stretch_after = report.stretch_after;
      stats_.optimization_sweeps = report.sweeps;
    }
  }
  ScopedStage stage(stats_.times, progress_, Stage::Embedding);
  all_.V = ShellEmbedding(*map_).embed(mapped_);
  place_by_normal(by_normal_);
  if (!options_.optimize_stretch) return;
  pairs_ = all_face_pairs(all_.V, all_.F);
  known_disjoint_ = pairs_.empty();  // nothing to revert, nor for post-processing to find
  std::vector<char> touching(ne_, 0);
  for (const auto& [f, g] : pairs_)
    touching[static_cast<size_t>(element_of_[f])] = touching[static_cast<size_t>(element_of_[g])] =
        1;
  for (size_t k = 0; k < ne_; ++k) {
    if (!touching[k] || by_normal_[k]) continue;
    all_.V.middleRows(first_[k], first_[k + 1] - first_[k]) =
        unoptimized.middleRows(first_[k], first_[k + 1] - first_[k]);
    stale_[k] = 1;
    ++stats_.unoptimized_elements;
  }
  // Their pairs are found again after the fold repair, which moves some of them too.
  have_pairs_ = true;
}

// The layout's versions of elements placed as even copies, embedded as the copies are (through
// the map where all their faces have a shell, else by normal displacement): tried before such a
// copy is removed (try_layout_versions).
void QuiltEmbedder::embed_layout_versions() {
  alternative_first_.assign(ne_ + 1, 0);
  for (size_t k = 0; k < ne_; ++k)
    alternative_first_[k + 1] =
        alternative_first_[k] +
        static_cast<Eigen::Index>(quilt_.elements[k].through_layout.face.size());
  if (alternative_first_.back() == 0) return;
  LocalCoordinates alt;
  const Eigen::Index na = alternative_first_.back();
  alt.face.resize(na);
  alt.bary.resize(na, 3);
  alt.height.resize(na);
  std::vector<char>& alt_normal = alternative_by_normal_;
  alt_normal.assign(ne_, map_ ? 0 : 1);
  for (size_t k = 0; k < ne_; ++k) {
    const SurfaceElement::Alternative& a = quilt_.elements[k].through_layout;
    for (size_t v = 0; v < a.face.size(); ++v) {
      const Eigen::Index i = alternative_first_[k] + static_cast<Eigen::Index>(v);
      alt.face(i) = a.face[v];
      alt.bary.row(i) = a.barycentric.row(static_cast<Eigen::Index>(v));
      alt.height(i) = std::clamp(a.height(static_cast<Eigen::Index>(v)), 0.0, quilt_.shell_height);
      if (map_ && map_->shell_face(a.face[v]) < 0) alt_normal[k] = 1;
    }
  }
  alternative_V_ = normal_displacement(quilt_.base.V, quilt_.base.F, shell_directions(), alt);
  if (!map_) return;
  LocalCoordinates through = alt;
  for (size_t k = 0; k < ne_; ++k)
    for (Eigen::Index i = alternative_first_[k]; i < alternative_first_[k + 1]; ++i)
      through.face(i) = alt_normal[k] ? 0 : map_->shell_face(alt.face(i));
  const MatrixX3d mapped_alt = ShellEmbedding(*map_).embed(through);
  for (size_t k = 0; k < ne_; ++k)
    if (!alt_normal[k])
      alternative_V_.middleRows(alternative_first_[k],
                                alternative_first_[k + 1] - alternative_first_[k]) =
          mapped_alt.middleRows(alternative_first_[k],
                                alternative_first_[k + 1] - alternative_first_[k]);
}

// Rings whose layout version threads more of their neighbours than their even copy does take
// it (core/shell/linked_versions); the copy becomes the other version.
void QuiltEmbedder::choose_linked_versions() {
  if (alternative_V_.rows() == 0) return;
  // Timed as part of the embedding (it chooses between two embedded versions), without a
  // second progress line for it.
  ScopedStageTimer timer(stats_.times, Stage::Embedding);
  LinkedVersionStats linked;
  const std::vector<char> swapped =
      mq::choose_linked_versions(quilt_, first_, all_.V, alternative_V_, alternative_first_,
                                 std::vector<char>(ne_, 0), {}, &linked);
  // A swapped ring's intersecting pairs are found again (the pairs found after the embedding
  // are of its copy).
  for (size_t k = 0; k < ne_; ++k)
    if (swapped[k]) {
      std::swap(by_normal_[k], alternative_by_normal_[k]);
      stale_[k] = 1;
      known_disjoint_ = false;
    }
  stats_.linked_versions = linked.chosen;
}

// The check (issue 23): every vertex's signed height over the base as given. An element under
// the base (the shell map of a base whose shell could only be made over a repaired copy, say) is
// placed again by normal displacement; one still under it is removed at the end. Elements moved
// by the repairs that follow are checked again before the output.
void QuiltEmbedder::check_placement() {
  if (first_.back() == 0) return;
  ScopedStage stage(stats_.times, progress_, Stage::PlacementCheck);
  base_height_.emplace(quilt_.input_base.V, quilt_.input_base.F);
  heights_ = check_element_heights(*base_height_, all_.V, first_, check_);
  stats_.below_base_embedded = placement_figures(heights_).below_share();
  std::vector<char> again(ne_, 0);
  for (size_t k = 0; k < ne_; ++k)
    if (heights_[k].below > 0) {
      if (by_normal_[k])
        sunk_[k] = 1;
      else
        again[k] = 1;
    }
  stats_.replaced_below = static_cast<int>(std::count(again.begin(), again.end(), 1));
  if (stats_.replaced_below == 0) return;
  place_by_normal(again);
  const std::vector<ElementHeights> rechecked =
      check_element_heights(*base_height_, all_.V, first_, check_, again);
  for (size_t k = 0; k < ne_; ++k)
    if (again[k]) {
      heights_[k] = rechecked[k];
      sunk_[k] = rechecked[k].below > 0;
      stale_[k] = 1;
    }
  known_disjoint_ = false;
}

// Elements to be removed for lying under the base take no part in the repairs: their face pairs
// are forgotten.
void QuiltEmbedder::forget_sunk(std::vector<std::pair<int, int>>& p) const {
  if (std::find(sunk_.begin(), sunk_.end(), 1) == sunk_.end()) return;
  p.erase(std::remove_if(p.begin(), p.end(),
                         [&](const std::pair<int, int>& q) {
                           return sunk_[static_cast<size_t>(element_of_[q.first])] ||
                                  sunk_[static_cast<size_t>(element_of_[q.second])];
                         }),
          p.end());
}

void QuiltEmbedder::find_pairs_once() {
  if (have_pairs_) return;
  pairs_ = all_face_pairs(all_.V, all_.F);
  forget_sunk(pairs_);
  have_pairs_ = true;
}

void QuiltEmbedder::update_pairs(const std::vector<char>& moved) {
  pairs_ = updated_face_pairs(all_.V, all_.F, first_, element_of_, std::move(pairs_), moved);
  forget_sunk(pairs_);
}

// Elements the repairs pushed under the base (a folded element's flat shape fitted over a curved
// base, a ring moved away from its neighbours: on the armor job 323 rings, up to 0.43 H deep)
// are lifted out whole, after the fold repair (so that ring separation can part the lifted
// rings from those they then touch) and after ring separation. Returns which elements moved;
// their pairs are left to the caller's next update.
std::vector<char> QuiltEmbedder::lift_moved() {
  std::vector<char> lifted(ne_, 0);
  if (heights_.empty() || std::find(moved_after_check_.begin(), moved_after_check_.end(), 1) ==
                              moved_after_check_.end())
    return lifted;
  const std::vector<ElementHeights> rechecked =
      check_element_heights(*base_height_, all_.V, first_, check_, moved_after_check_);
  std::vector<char> lift(ne_, 0);
  for (size_t k = 0; k < ne_; ++k)
    if (moved_after_check_[k]) {
      heights_[k] = rechecked[k];
      lift[k] = rechecked[k].below > 0 && !sunk_[k];
    }
  std::fill(moved_after_check_.begin(), moved_after_check_.end(), 0);
  if (std::find(lift.begin(), lift.end(), 1) == lift.end()) return lifted;
  const std::vector<ElementHeights> after =
      lift_out_of_base(*base_height_, all_.V, first_, check_, lift, 4, &lifted);
  for (size_t k = 0; k < ne_; ++k)
    if (lift[k]) heights_[k] = after[k];
  stats_.lifted_below += static_cast<int>(std::count(lifted.begin(), lifted.end(), 1));
  known_disjoint_ = false;
  return lifted;
}

// Repair (issue 13): an element the map folds through itself is replaced by its flat shape
// fitted where the map put it, as little as removes the fold (core/shell/element_unfolding).
void QuiltEmbedder::repair_folds() {
  ScopedStage stage(stats_.times, progress_, Stage::FoldRepair);
  if (!known_disjoint_) find_pairs_once();
  // Folded: a pair within the element, or for an element moved since the pairs were found (kept
  // on the unoptimised map), its own test; with the pair (in the element's own face numbers),
  // which the unfolding tries first on each blend.
  std::vector<char> folded_now(ne_, 0);
  std::vector<std::pair<int, int>> fold(ne_, {-1, -1});
  std::vector<int> first_face(ne_ + 1, 0);  // all_.F holds the elements' faces in order
  for (size_t k = 0; k < ne_; ++k)
    first_face[k + 1] = first_face[k] + static_cast<int>(quilt_.elements[k].F.rows());
  for (const auto& [f, g] : pairs_) {
    const auto k = static_cast<size_t>(element_of_[f]);
    if (element_of_[f] != element_of_[g] || stale_[k] || folded_now[k]) continue;
    folded_now[k] = 1;
    fold[k] = {f - first_face[k], g - first_face[k]};
  }
  tbb::parallel_for(size_t{0}, ne_, [&](size_t k) {
    if (stale_[k])
      folded_now[k] =
          self_intersects(MatrixX3d(all_.V.middleRows(first_[k], first_[k + 1] - first_[k])),
                          quilt_.elements[k].F, &fold[k]);
  });
  tbb::parallel_for(size_t{0}, ne_, [&](size_t k) {
    const SurfaceElement& e = quilt_.elements[k];
    const Eigen::Index v0 = first_[k], ev = first_[k + 1] - first_[k];
    if (!folded_now[k] || e.flat.rows() != ev) {
      folded_now[k] = 0;  // left as it is
      return;
    }
    all_.V.middleRows(v0, ev) =
        unfold_element(all_.V.middleRows(v0, ev), e.flat, e.F,
                       base_height_ ? &*base_height_ : nullptr, check_, fold[k]);
  });
  for (size_t k = 0; k < ne_; ++k) {
    stats_.rigid_repairs += folded_now[k];
    stale_[k] = stale_[k] || folded_now[k];
    moved_after_check_[k] = moved_after_check_[k] || folded_now[k];
  }
  if (options_.unbend_rings) {
    const std::vector<char> absent = absent_elements();
    RingUnbendingStats unbending;
    unbend_folded_rings(absent, unbending);
    stats_.folded_rings = unbending.folded;
    stats_.unbent_rings = unbending.unbent;
    absent_at_unbending_ = absent;
  }
  const std::vector<char> lifted = lift_moved();
  for (size_t k = 0; k < ne_; ++k) {
    stale_[k] = stale_[k] || lifted[k];
    moved_since_unbending_[k] = moved_since_unbending_[k] || lifted[k];
  }
  if (!have_pairs_) return;
  update_pairs(stale_);
  std::fill(stale_.begin(), stale_.end(), 0);
}

std::vector<char> QuiltEmbedder::absent_elements() const {
  std::vector<char> absent(ne_, 0);
  for (size_t k = 0; k < ne_; ++k) absent[k] = drop_[k] || sunk_[k];
  return absent;
}

// Rings folded over edges they cannot follow hang over them rigidly instead
// (core/shell/ring_unbending), among the elements not `absent`. Returns which moved (stale and
// to be checked again).
std::vector<char> QuiltEmbedder::unbend_folded_rings(const std::vector<char>& absent,
                                                     RingUnbendingStats& unbending,
                                                     const std::vector<char>* candidates) {
  std::vector<const MatrixX3i*> faces(ne_);
  std::vector<const MatrixX3d*> flat(ne_);
  for (size_t k = 0; k < ne_; ++k) {
    faces[k] = &quilt_.elements[k].F;
    flat[k] = &quilt_.elements[k].flat;
  }
  const std::vector<char> moved = mq::unbend_folded_rings(all_.V, first_, faces, flat, absent,
                                                          base_height_ ? &*base_height_ : nullptr,
                                                          check_, {}, &unbending, candidates);
  for (size_t k = 0; k < ne_; ++k) {
    stale_[k] = stale_[k] || moved[k];
    moved_after_check_[k] = moved_after_check_[k] || moved[k];
  }
  return moved;
}

// Rings pressed into each other are moved apart whole, links kept (core/shell/ring_separation);
// what still touches is left to the post-processing. Armor job: interior rings with the
// swatch's 4 links 84.2 -> 91.3%, rings removed 122 -> 32.
std::vector<char> QuiltEmbedder::separate_touching_rings(const std::vector<char>* absent) {
  if (!have_pairs_) return std::vector<char>(ne_, 0);
  ScopedStage stage(stats_.times, progress_, Stage::RingSeparation);
  const auto is_absent = [&](int k) { return absent && (*absent)[static_cast<size_t>(k)]; };
  std::vector<char> touching(ne_, 0), folded_now(ne_, 0);
  for (const auto& [f, g] : pairs_) {
    const int a = element_of_[f], b = element_of_[g];
    if (is_absent(a) || is_absent(b)) continue;
    if (a == b)
      folded_now[static_cast<size_t>(a)] = 1;
    else
      touching[static_cast<size_t>(a)] = touching[static_cast<size_t>(b)] = 1;
  }
  for (size_t k = 0; k < ne_; ++k) touching[k] = touching[k] && !folded_now[k];
  if (std::find(touching.begin(), touching.end(), 1) == touching.end())
    return std::vector<char>(ne_, 0);
  const ElementGrid grid(all_.V, first_, std::vector<char>(ne_, 0));
  std::vector<char> near(ne_, 0);
  for (size_t k = 0; k < ne_; ++k)
    if (touching[k]) {
      near[k] = 1;
      for (const int j : grid.near(grid.box[k])) near[static_cast<size_t>(j)] = 1;
    }
  // Each ring binned on its flat shape (a ring the map bent keeps its cross sections). Absent
  // elements get no binning: neither moved nor obstacles.
  std::vector<std::optional<RingBins>> bins(ne_), link_bins(ne_);
  tbb::parallel_for(size_t{0}, ne_, [&](size_t k) {
    if (!near[k] || folded_now[k] || is_absent(static_cast<int>(k))) return;
    const SurfaceElement& e = quilt_.elements[k];
    const Eigen::Index ev = static_cast<Eigen::Index>(e.face.size());
    const MatrixX3d placed = all_.V.middleRows(first_[k], ev);
    link_bins[k] = ring_loop_bins(placed, e.F);
    if (!link_bins[k]) return;
    bins[k] = e.flat.rows() == ev ? ring_loop_bins(e.flat, e.F) : link_bins[k];
  });
  const MatrixX3d before = all_.V;
  RingSeparationStats sep;
  RingSeparationOptions separation;
  separation.ground = &*base_height_;  // apart, but not into the base
  std::vector<char> moved =
      separate_rings(all_.V, first_, bins, link_bins, touching, separation, &sep);
  const int left_shell =
      keep_in_shell(quilt_, first_, before, all_.V, moved, *base_height_, check_);
  stats_.separation_left_shell += left_shell;
  stats_.separated_rings += sep.moved - left_shell;
  stats_.separation_reverted += sep.reverted;
  stats_.separation_iterations = std::max(stats_.separation_iterations, sep.iterations);
  for (size_t k = 0; k < ne_; ++k) moved_after_check_[k] = moved_after_check_[k] || moved[k];
  const std::vector<char> lifted = lift_moved();
  for (size_t k = 0; k < ne_; ++k) {
    moved[k] = moved[k] || lifted[k];
    moved_since_unbending_[k] = moved_since_unbending_[k] || moved[k];
  }
  update_pairs(moved);
  return moved;
}

// Post-processing (issue 13: no folded element reaches the output; core/shell/element_removal):
// an element that intersects itself goes; of intersecting elements as few as can go, and those
// are tried again as the layout placed them, then smaller. After ring separation 32 of the
// armor's rings are left to remove instead of 122.
void QuiltEmbedder::remove_intersecting() {
  if (known_disjoint_) return;
  ScopedStage stage(stats_.times, progress_, Stage::ElementRemoval);
  find_pairs_once();
  choose_removals(pairs_, element_of_, drop_, folded_);
  // Folded and sunk elements are not tried again.
  std::vector<char> skip = folded_;
  for (size_t k = 0; k < ne_; ++k) skip[k] = skip[k] || sunk_[k];
  const std::vector<char> back =
      try_layout_versions(quilt_, first_, skip, alternative_V_, alternative_first_, all_.V, drop_);
  for (size_t k = 0; k < ne_; ++k)
    if (back[k]) {
      moved_after_check_[k] = restored_[k] = 1;
      ++stats_.layout_versions;
    }
  if (!options_.shrink_to_fit) return;
  const std::vector<char> dropped = drop_;
  for (size_t k = 0; k < ne_; ++k) drop_[k] = drop_[k] || sunk_[k];
  stats_.shrunk_to_fit = shrink_to_fit(quilt_, first_, skip, all_.V, drop_);
  for (size_t k = 0; k < ne_; ++k)
    if (dropped[k] && !drop_[k]) moved_after_check_[k] = restored_[k] = 1;
}

// Rings still folded after the removal (a layout version brought back there, a ring the
// separation pressed into a fold) hang over their edge too: the fold repair's unbending once
// more, the separation for the kept rings they then press, and any ring moved here that still
// meets a kept element goes back to where the removal left it, where the kept elements are
// disjoint. Folded rings in the output and interior rings with 4 links, this pass alone (before
// a ring could hang with half its links): bunny + link 11 -> 3, 94.33 -> 95.45%; armor 39 ->
// 33, 83.31 -> 83.77%; Spot 5 -> 4, 96.22 -> 96.35%.
void QuiltEmbedder::unbend_kept_folds() {
  const std::vector<char> absent = absent_elements();
  // Candidates: the rings whose neighbourhood changed since the fold repair's unbending (a ring
  // brought back, moved, dropped), found by boxes grown by a tenth (so that a ring moved a little
  // away still counts); any other folded ring would fail again as it did then.
  std::vector<char> candidates(ne_, 0);
  {
    ScopedStage stage(stats_.times, progress_, Stage::FoldRepair);
    const ElementGrid grid(all_.V, first_, std::vector<char>(ne_, 0));
    for (size_t k = 0; k < ne_; ++k) {
      if (!restored_[k] && !moved_since_unbending_[k] && absent[k] == absent_at_unbending_[k])
        continue;
      BoundingBox b = grid.box[k];
      const Vector3d grow = Vector3d::Constant(0.1 * b.extent().maxCoeff());
      b.min -= grow;
      b.max += grow;
      for (const int j : grid.near(b)) candidates[static_cast<size_t>(j)] = 1;
      candidates[k] = 1;
    }
  }
  if (std::find(candidates.begin(), candidates.end(), 1) == candidates.end()) return;
  const MatrixX3d before = all_.V;
  std::vector<char> unbent;
  {
    ScopedStage stage(stats_.times, progress_, Stage::FoldRepair);
    RingUnbendingStats unbending;
    unbent = unbend_folded_rings(absent, unbending, &candidates);
    if (unbending.unbent == 0) return;
    // The removal checked the rings it brought back against every kept element, not their pairs:
    // theirs are those from before, found again here only beside the rings unbent now.
    find_pairs_once();
    pairs_.erase(std::remove_if(pairs_.begin(), pairs_.end(),
                                [&](const std::pair<int, int>& p) {
                                  return restored_[static_cast<size_t>(element_of_[p.first])] ||
                                         restored_[static_cast<size_t>(element_of_[p.second])];
                                }),
                 pairs_.end());
    update_pairs(unbent);
    std::fill(stale_.begin(), stale_.end(), 0);
  }
  std::vector<char> moved = unbent;
  if (options_.separate_rings) {
    const std::vector<char> separated = separate_touching_rings(&absent);
    for (size_t k = 0; k < ne_; ++k) moved[k] = moved[k] || separated[k];
  }
  ScopedStage stage(stats_.times, progress_, Stage::FoldRepair);
  for (;;) {
    std::vector<char> back(ne_, 0);
    for (const auto& [f, g] : pairs_) {
      const auto a = static_cast<size_t>(element_of_[f]), b = static_cast<size_t>(element_of_[g]);
      if (absent[a] || absent[b]) continue;
      back[a] = back[a] || moved[a];
      back[b] = back[b] || moved[b];
    }
    if (std::find(back.begin(), back.end(), 1) == back.end()) break;
    for (size_t k = 0; k < ne_; ++k)
      if (back[k]) {
        all_.V.middleRows(first_[k], first_[k + 1] - first_[k]) =
            before.middleRows(first_[k], first_[k + 1] - first_[k]);
        moved[k] = 0;
        moved_after_check_[k] = 1;
        stats_.late_unbending_reverted += unbent[k];
      }
    update_pairs(back);
  }
  for (size_t k = 0; k < ne_; ++k) stats_.late_unbent_rings += unbent[k] && moved[k];
}

// The last word of the check: elements moved since are measured again, and every element still
// under the base is removed; the output's figures.
void QuiltEmbedder::check_output() {
  if (heights_.empty()) return;
  ScopedStage stage(stats_.times, progress_, Stage::PlacementCheck);
  for (size_t k = 0; k < ne_; ++k) moved_after_check_[k] = moved_after_check_[k] && !drop_[k];
  if (std::find(moved_after_check_.begin(), moved_after_check_.end(), 1) !=
      moved_after_check_.end()) {
    const std::vector<ElementHeights> rechecked =
        check_element_heights(*base_height_, all_.V, first_, check_, moved_after_check_);
    for (size_t k = 0; k < ne_; ++k)
      if (moved_after_check_[k]) heights_[k] = rechecked[k];
  }
  std::vector<char> kept(ne_, 0);
  for (size_t k = 0; k < ne_; ++k) {
    if (!drop_[k] && (sunk_[k] || heights_[k].below > 0)) {
      drop_[k] = 1;
      sunk_[k] = 1;
    }
    kept[k] = !drop_[k];
  }
  const PlacementFigures output = placement_figures(heights_, kept);
  stats_.checked_vertices = output.vertices;
  stats_.below_base = output.below_share();
  stats_.above_shell = output.above_share();
  stats_.lowest_height = output.lowest / quilt_.shell_height;
}

// The kept elements, in order, and the spread of their areas (how even the texture is).
TriMesh QuiltEmbedder::output() {
  TriMesh out;
  out.kinds = quilt_.kinds;
  Eigen::Index kv = 0, kf = 0;
  for (size_t k = 0; k < ne_; ++k)
    if (!drop_[k]) {
      kv += first_[k + 1] - first_[k];
      kf += quilt_.elements[k].F.rows();
    }
  out.V.resize(kv, 3);
  out.F.resize(kf, 3);
  kv = kf = 0;
  std::vector<double> areas;
  for (size_t k = 0; k < ne_; ++k) {
    const SurfaceElement& e = quilt_.elements[k];
    const Eigen::Index v0 = first_[k], ev = first_[k + 1] - first_[k], ef = e.F.rows();
    if (drop_[k]) {
      ++(sunk_[k]     ? stats_.removed_below
         : folded_[k] ? stats_.removed_self_intersecting
                      : stats_.removed_intersecting);
      continue;
    }
    stats_.kept.push_back(static_cast<int>(k));
    out.V.middleRows(kv, ev) = all_.V.middleRows(v0, ev);
    out.F.middleRows(kf, ef) = e.F.array() + static_cast<int>(kv);
    out.face_kind.insert(out.face_kind.end(), static_cast<size_t>(ef), e.kind);
    areas.push_back(face_areas(all_.V.middleRows(v0, ev), e.F).sum());
    kv += ev;
    kf += ef;
  }
  stats_.faces = out.num_faces();
  stats_.vertices = out.num_vertices();
  stats_.elements = static_cast<int>(areas.size());
  if (areas.empty()) return out;
  double mean = 0, var = 0;
  for (const double a : areas) mean += a;
  mean /= static_cast<double>(areas.size());
  for (const double a : areas) var += (a - mean) * (a - mean);
  var /= static_cast<double>(areas.size());
  stats_.element_area_mean = mean;
  stats_.element_area_cv = mean > 0 ? std::sqrt(var) / mean : 0;
  stats_.element_area_min = *std::min_element(areas.begin(), areas.end());
  stats_.element_area_max = *std::max_element(areas.begin(), areas.end());
  return out;
}

// Sampled at the refined base's face centroids (edges at most 0.3 of the swatch side): the
// input's faces can be far larger than the swatch (the brick wall's 84 faces made the figure
// jump by 0.2 between runs of nearly identical output). Only geometry on the base's outer side
// counts (issue 23: texture inside the base covered the open quadruped's legs from within).
void QuiltEmbedder::measure_coverage(const TriMesh& out) {
  ScopedStage stage(stats_.times, progress_, Stage::Coverage);
  stats_.coverage =
      surface_coverage(quilt_.base, out, 1.5 * quilt_.shell_height,
                       stats_.placement_tolerance * quilt_.shell_height, options_.coverage_faces);
}

}  // namespace

TriMesh embed_quilt(const SurfaceQuilt& quilt, const QuiltEmbeddingOptions& options,
                    TetStretchEvaluator& stretch, QuiltEmbeddingStats* stats_out,
                    ProgressSink* progress) {
  QuiltEmbeddingStats stats;
  QuiltEmbedder embedding(quilt, options, stats, progress);
  if (options.shell_map && !embedding.empty()) embedding.build_shell_map();
  embedding.embed(stretch);
  if (options.remove_intersecting) {
    embedding.embed_layout_versions();
    if (options.choose_linked_versions) embedding.choose_linked_versions();
  }
  embedding.check_placement();
  if (options.remove_intersecting) {
    embedding.repair_folds();
    if (options.separate_rings) embedding.separate_touching_rings();
    embedding.remove_intersecting();
    if (options.unbend_rings) embedding.unbend_kept_folds();
  }
  embedding.check_output();
  TriMesh out = embedding.output();
  embedding.measure_coverage(out);
  if (stats_out) *stats_out = std::move(stats);
  return out;
}

}  // namespace mq
