#include "core/shell/quilt_embedding.h"

#include <tbb/parallel_for.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/vertex_cover.h"
#include "core/shell/offset_surface.h"
#include "core/shell/placement_check.h"
#include "core/shell/ring_separation.h"
#include "core/shell/shell_embedding.h"
#include "core/shell/shell_map.h"
#include "core/shell/signed_height.h"
#include "core/shell/surface_coverage.h"

namespace mq {

namespace {

// The similarity (scale, rotation, translation) taking `from` nearest to `to` in the least
// squares sense, applied to `from` (Umeyama 1991). Both #V by 3, corresponding rows.
MatrixX3d similarity_fit(const MatrixX3d& from, const MatrixX3d& to) {
  const Vector3d cf = from.colwise().mean().transpose(), ct = to.colwise().mean().transpose();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var = 0;
  for (Eigen::Index i = 0; i < from.rows(); ++i) {
    const Vector3d a = from.row(i).transpose() - cf, b = to.row(i).transpose() - ct;
    cov += b * a.transpose();
    var += a.squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) S(2, 2) = -1;
  const Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  const double scale = var > 0 ? (svd.singularValues().asDiagonal() * S).trace() / var : 1.0;
  MatrixX3d out(from.rows(), 3);
  for (Eigen::Index i = 0; i < from.rows(); ++i)
    out.row(i) = (ct + scale * R * (from.row(i).transpose() - cf)).transpose();
  return out;
}

// Element boxes in a uniform grid (cell: the median element size; a box larger than a few
// cells is rare), to find the elements near a box in about constant time.
class ElementGrid {
 public:
  // first: #elements+1 offsets of each element's rows in V; elements with skip[k] set (or
  // no vertices) are left out until insert()ed.
  ElementGrid(const MatrixX3d& V, const std::vector<Eigen::Index>& first,
              const std::vector<char>& skip) {
    const size_t ne = first.size() - 1;
    box.resize(ne);
    std::vector<double> sizes;
    for (size_t k = 0; k < ne; ++k) {
      for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) box[k].extend(V.row(v).transpose());
      if (first[k + 1] > first[k]) sizes.push_back(box[k].extent().maxCoeff());
    }
    if (sizes.empty()) return;
    std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
    cell_ = std::max(sizes[sizes.size() / 2], 1e-12);
    origin_ = bounding_box(V).min;
    for (size_t k = 0; k < ne; ++k)
      if (!skip[k] && first[k + 1] > first[k]) insert(static_cast<int>(k), box[k]);
  }
  void insert(int k, const BoundingBox& b) {
    box[static_cast<size_t>(k)] = b;
    for_cells(b, [&](unsigned long long c) { grid_[c].push_back(k); });
  }
  // The inserted elements whose box meets b, ascending.
  std::vector<int> near(const BoundingBox& b) const {
    std::vector<int> found;
    for_cells(b, [&](unsigned long long c) {
      if (const auto it = grid_.find(c); it != grid_.end())
        for (const int j : it->second)
          if (overlap(b, box[static_cast<size_t>(j)])) found.push_back(j);
    });
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
    return found;
  }
  static bool overlap(const BoundingBox& a, const BoundingBox& b) {
    return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
  }
  std::vector<BoundingBox> box;

 private:
  template <class Visit>
  void for_cells(const BoundingBox& b, Visit&& visit) const {
    if (grid_.empty() && cell_ == 0) return;
    const auto cell_of = [&](const Vector3d& p) {
      return ((p - origin_) / cell_).array().floor().cast<long long>().eval();
    };
    const auto lo = cell_of(b.min), hi = cell_of(b.max);
    for (long long x = lo(0); x <= hi(0); ++x)
      for (long long y = lo(1); y <= hi(1); ++y)
        for (long long z = lo(2); z <= hi(2); ++z)
          visit(static_cast<unsigned long long>(x) * 0x9E3779B97F4A7C15ull ^
                static_cast<unsigned long long>(y) * 0xC2B2AE3D27D4EB4Full ^
                static_cast<unsigned long long>(z) * 0x165667B19E3779F9ull);
  }
  double cell_ = 0;
  Vector3d origin_ = Vector3d::Zero();
  std::unordered_map<unsigned long long, std::vector<int>> grid_;
};

// Every intersecting face pair, within an element (a fold) and between two.
std::vector<std::pair<int, int>> all_face_pairs(const MatrixX3d& V, const MatrixX3i& F) {
  IntersectionOptions all_pairs;
  all_pairs.between_components_only = false;
  return intersecting_face_pairs(V, F, all_pairs);
}

std::vector<Eigen::Index> vertex_offsets(const SurfaceQuilt& quilt) {
  std::vector<Eigen::Index> first(quilt.elements.size() + 1, 0);
  for (size_t k = 0; k < quilt.elements.size(); ++k)
    first[k + 1] = first[k] + static_cast<Eigen::Index>(quilt.elements[k].face.size());
  return first;
}

// The intersecting face pairs of (V, F) (all pairs, as intersecting_face_pairs with
// between_components_only false) after the elements marked `changed` moved, from the pairs
// found before they did: the pairs of unchanged elements stay, those of changed elements are
// found again among the faces of the elements whose boxes meet theirs. The same sorted pairs
// as a full pass, for the cost of the changed elements' neighbourhoods (the fold repair moves
// 274 of the armor's 1,944 rings; a full pass over its 2.2M faces took ~1 s).
std::vector<std::pair<int, int>> updated_pairs(const SurfaceQuilt& quilt, const MatrixX3d& V,
                                               const MatrixX3i& F,
                                               const std::vector<int>& element_of,
                                               std::vector<std::pair<int, int>> pairs,
                                               const std::vector<char>& changed) {
  if (std::find(changed.begin(), changed.end(), 1) == changed.end()) return pairs;
  const auto is_changed = [&](int f) { return changed[static_cast<size_t>(element_of[f])] != 0; };
  pairs.erase(std::remove_if(pairs.begin(), pairs.end(),
                             [&](const std::pair<int, int>& p) {
                               return is_changed(p.first) || is_changed(p.second);
                             }),
              pairs.end());
  const std::vector<Eigen::Index> first = vertex_offsets(quilt);
  const ElementGrid grid(V, first, std::vector<char>(quilt.elements.size(), 0));
  std::vector<char> take(quilt.elements.size(), 0);
  for (size_t k = 0; k < quilt.elements.size(); ++k)
    if (changed[k]) {
      take[k] = 1;
      for (const int j : grid.near(grid.box[k])) take[static_cast<size_t>(j)] = 1;
    }
  std::vector<int> faces;  // global face indices of the subset, ascending
  for (int f = 0; f < F.rows(); ++f)
    if (take[static_cast<size_t>(element_of[f])]) faces.push_back(f);
  MatrixX3i sub(static_cast<Eigen::Index>(faces.size()), 3);
  std::vector<char> active(faces.size(), 0);
  for (size_t i = 0; i < faces.size(); ++i) {
    sub.row(static_cast<Eigen::Index>(i)) = F.row(faces[i]);
    active[i] = is_changed(faces[i]);
  }
  // Only the changed elements' faces drive the test (the neighbours' pairs among themselves
  // are already known): armor job, 1.0 -> 0.3 s per update.
  for (const auto& [a, b] : intersecting_face_pairs_touching(V, sub, active))
    pairs.emplace_back(faces[static_cast<size_t>(a)], faces[static_cast<size_t>(b)]);
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// Elements dropped for touching a neighbour that have a version placed through the layout
// (alternative rows first[k]..first[k + 1] of A) take it when it clears every kept element and
// does not fold: an even copy of an element pressed into its neighbours (around a cone, where
// the layout's spacing is smaller than the element) gives way to the layout's own, distorted
// but threaded through its neighbours as the lattice is. Elements flagged in `skip` stay out.
// Returns the elements that came back (V's rows replaced, drop cleared).
std::vector<char> try_alternatives(const SurfaceQuilt& quilt, const std::vector<char>& skip,
                                   const MatrixX3d& A,
                                   const std::vector<Eigen::Index>& alternative_first, MatrixX3d& V,
                                   std::vector<char>& drop) {
  const size_t ne = quilt.elements.size();
  std::vector<char> restored(ne, 0);
  if (A.rows() == 0) return restored;
  const std::vector<Eigen::Index> first = vertex_offsets(quilt);
  ElementGrid grid(V, first, drop);
  auto element_mesh = [&](size_t k) {
    TriMesh m;
    m.V = V.middleRows(first[k], first[k + 1] - first[k]);
    m.F = quilt.elements[k].F;
    return m;
  };
  for (size_t k = 0; k < ne; ++k) {
    const Eigen::Index n = alternative_first[k + 1] - alternative_first[k];
    if (!drop[k] || skip[k] || n == 0 || n != first[k + 1] - first[k]) continue;
    TriMesh m;
    m.V = A.middleRows(alternative_first[k], n);
    m.F = quilt.elements[k].F;
    if (!self_intersecting_components(m.V, m.F).empty()) continue;
    BoundingBox b;
    for (Eigen::Index v = 0; v < m.V.rows(); ++v) b.extend(m.V.row(v).transpose());
    bool clear = true;
    for (const int j : grid.near(b))
      if (static_cast<size_t>(j) != k && !drop[j] && meshes_intersect(m, element_mesh(j))) {
        clear = false;
        break;
      }
    if (!clear) continue;
    V.middleRows(first[k], n) = m.V;
    drop[k] = 0;
    grid.insert(static_cast<int>(k), b);
    restored[k] = 1;
  }
  return restored;
}

// Elements dropped for touching a neighbour are tried again a little smaller about their
// centres (chain mail has clearance between linked rings: a ring pushed into its neighbour over
// a crease usually clears it at 90% of its size and still threads it). `V` holds every
// element's vertices in order; a kept shrunken element overwrites its rows and its `drop` flag.
// Neighbours are found through the element grid, so this is linear in the number of elements.
// Returns how many elements came back.
int shrink_to_fit(const SurfaceQuilt& quilt, const std::vector<char>& folded, MatrixX3d& V,
                  std::vector<char>& drop) {
  const size_t ne = quilt.elements.size();
  const std::vector<Eigen::Index> first = vertex_offsets(quilt);
  ElementGrid grid(V, first, drop);
  auto element_mesh = [&](size_t k) {
    TriMesh m;
    m.V = V.middleRows(first[k], first[k + 1] - first[k]);
    m.F = quilt.elements[k].F;
    return m;
  };
  int restored = 0;
  for (size_t k = 0; k < ne; ++k) {
    if (!drop[k] || folded[k] || first[k + 1] == first[k]) continue;
    const TriMesh original = element_mesh(k);
    const Vector3d c = original.V.colwise().mean().transpose();
    for (const double factor : {0.95, 0.9, 0.85}) {
      TriMesh m = original;
      for (Eigen::Index v = 0; v < m.V.rows(); ++v)
        m.V.row(v) = (c + factor * (m.V.row(v).transpose() - c)).transpose();
      BoundingBox b;
      for (Eigen::Index v = 0; v < m.V.rows(); ++v) b.extend(m.V.row(v).transpose());
      bool clear = true;
      for (const int j : grid.near(b))
        if (static_cast<size_t>(j) != k && !drop[j] && meshes_intersect(m, element_mesh(j))) {
          clear = false;
          break;
        }
      if (!clear) continue;
      V.middleRows(first[k], m.V.rows()) = m.V;
      drop[k] = 0;
      grid.insert(static_cast<int>(k), b);
      ++restored;
      break;
    }
  }
  return restored;
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

// The directions normal displacement follows, over the refined base: the shell's smoothed
// offset directions (core/shell/offset_surface). Its plain vertex normals fan out at a spike's tip
// (rings there pressed into each other: 72 removed on the spiky sphere against 20), and those of
// a coarse base as given shear a box's faces (a corner's is 55 degrees off each).
MatrixX3d shell_directions(const SurfaceQuilt& quilt) {
  return displacement_directions(quilt.base.V, quilt.base.F, quilt.shell_height);
}

// The rows of the elements with which[k] set placed by normal displacement (the fallback where
// the shell map is not built, or where it put an element under the base).
void place_by_normal(const SurfaceQuilt& quilt, const LocalCoordinates& points,
                     const std::vector<Eigen::Index>& first, const std::vector<char>& which,
                     MatrixX3d& V) {
  std::vector<Eigen::Index> rows;
  for (size_t k = 0; k + 1 < first.size(); ++k)
    if (which[k])
      for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) rows.push_back(v);
  if (rows.empty()) return;
  LocalCoordinates sub;
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  sub.face.resize(n);
  sub.bary.resize(n, 3);
  sub.height.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    sub.face(i) = points.face(rows[static_cast<size_t>(i)]);
    sub.bary.row(i) = points.bary.row(rows[static_cast<size_t>(i)]);
    sub.height(i) = points.height(rows[static_cast<size_t>(i)]);
  }
  const MatrixX3d placed =
      normal_displacement(quilt.base.V, quilt.base.F, shell_directions(quilt), sub);
  for (Eigen::Index i = 0; i < n; ++i) V.row(rows[static_cast<size_t>(i)]) = placed.row(i);
}

}  // namespace

TriMesh embed_quilt(const SurfaceQuilt& quilt, const QuiltEmbeddingOptions& options,
                    TetStretchEvaluator& stretch, QuiltEmbeddingStats* stats_out,
                    ProgressSink* progress) {
  QuiltEmbeddingStats stats;
  LocalCoordinates points;
  Eigen::Index nv = 0, nf = 0;
  for (const SurfaceElement& e : quilt.elements) {
    nv += static_cast<Eigen::Index>(e.face.size());
    nf += e.F.rows();
  }
  points.face.resize(nv);
  points.bary.resize(nv, 3);
  points.height.resize(nv);
  TriMesh all;
  all.F.resize(nf, 3);
  std::vector<int> element_of(nf);
  nv = nf = 0;
  for (size_t k = 0; k < quilt.elements.size(); ++k) {
    const SurfaceElement& e = quilt.elements[k];
    for (size_t v = 0; v < e.face.size(); ++v) {
      points.face(nv + v) = e.face[v];
      points.bary.row(nv + v) = e.barycentric.row(v);
      points.height(nv + v) = std::clamp(e.height(v), 0.0, quilt.shell_height);
    }
    all.F.middleRows(nf, e.F.rows()) = e.F.array() + static_cast<int>(nv);
    std::fill(element_of.begin() + nf, element_of.begin() + nf + e.F.rows(), static_cast<int>(k));
    nv += static_cast<Eigen::Index>(e.face.size());
    nf += e.F.rows();
  }
  const size_t ne = quilt.elements.size();
  const std::vector<Eigen::Index> first = vertex_offsets(quilt);
  std::unique_ptr<ShellMap> map;
  if (options.shell_map && nv > 0) {
    ShellMapOptions map_options;
    map_options.height = quilt.shell_height;
    ScopedStageTimer timer(stats.times, "shell map");
    ScopedStageProgress shown(progress, "shell map");
    try {
      // Over the refined base, whose faces are no larger than a third of the swatch: over the
      // base as given, a coarse model's large faces interpolate its corners' offset directions
      // (a box corner's is 55 degrees off each face), and the shell over a whole face is sheared
      // and thinner (a cube's by 1/sqrt(3)): rings lay flattened and slanted on Blender's cube
      // (median aspect 1.33 against 1.05 over the refined cube).
      map = std::make_unique<ShellMap>(quilt.base.V, quilt.base.F, map_options);
      stats.atlas_charts = map->atlas().num_charts;
      stats.shell_smoothing_steps = map->offset().smoothing_steps;
      stats.fold_repaired_vertices = static_cast<int>(map->fold_repair().moved_vertices.size());
      const ShellExclusion& left_out = map->exclusion();
      stats.fallback_faces = static_cast<int>(left_out.faces.size());
      stats.fallback_area_share = left_out.area_share;
      stats.fallback_fold_faces = left_out.fold_faces;
      stats.fallback_reason = left_out.reason;
    } catch (const TopologyError& e) {
      // No valid shell of this height over this base, even without its worst regions: the
      // texture is still placed, by normal displacement, and the reason is reported.
      stats.shell_map_failure = e.what();
      stats.fallback_faces = quilt.base.num_faces();
      stats.fallback_area_share = 1;
      stats.fallback_reason = e.what();
    }
  }
  // Elements with a vertex over a face the shell map left out are placed whole by normal
  // displacement (per-region fallback); the others through the map, in its face numbering.
  std::vector<char> by_normal(ne, map ? 0 : 1);
  LocalCoordinates mapped = points;
  if (map) {
    for (size_t k = 0; k < ne; ++k)
      for (Eigen::Index v = first[k]; v < first[k + 1]; ++v)
        if (map->shell_face(points.face(v)) < 0) by_normal[k] = 1;
    for (size_t k = 0; k < ne; ++k)
      for (Eigen::Index v = first[k]; v < first[k + 1]; ++v)
        mapped.face(v) = by_normal[k] ? 0 : map->shell_face(points.face(v));
    stats.fallback_elements = static_cast<int>(std::count(by_normal.begin(), by_normal.end(), 1));
  }
  bool known_disjoint = false;  // no two elements of all.V intersect (already checked)
  // The intersecting face pairs of all.V (within an element and between two), once found kept
  // up to date as elements move (updated_pairs): one full pass instead of three.
  std::vector<std::pair<int, int>> pairs;
  bool have_pairs = false;
  // Elements moved since `pairs` was found (their pairs are out of date until updated_pairs).
  std::vector<char> stale(ne, 0);
  if (map) {
    // The unoptimised map creates no intersections where the base is concave (the shell is
    // valid and elements lie in it apart); the optimised one bends its tetrahedra a little, and
    // an element whose triangles span a bent tetrahedron boundary can then touch a neighbour
    // (chain mail over the knight: 8 face pairs of 2 rings, none without optimisation). Those
    // elements keep the unoptimised map.
    MatrixX3d unoptimized;
    if (options.optimize_stretch) {
      ScopedStageTimer timer(stats.times, "embedding");
      ScopedStageProgress shown(progress, "embedding");
      unoptimized = ShellEmbedding(*map).embed(mapped);
    }
    {
      ScopedStageTimer timer(stats.times, "stretch optimization");
      ScopedStageProgress shown(progress, "stretch optimization");
      stats.stretch_before = stats.stretch_after = map->stretch(stretch);
      if (options.optimize_stretch) {
        ShellOptimizeOptions o;
        o.seed = options.seed;
        const ShellOptimizeReport report = map->optimize(stretch, o);
        stats.stretch_after = report.stretch_after;
        stats.optimization_sweeps = report.sweeps;
      }
    }
    ScopedStageTimer timer(stats.times, "embedding");
    ScopedStageProgress shown(progress, "embedding");
    all.V = ShellEmbedding(*map).embed(mapped);
    place_by_normal(quilt, points, first, by_normal, all.V);
    if (options.optimize_stretch) {
      // Pairs of faces that intersect, within an element (it folds through itself) or between
      // two: both kinds keep the unoptimised map.
      pairs = all_face_pairs(all.V, all.F);
      // Nothing to revert: post-processing would find the same nothing.
      known_disjoint = pairs.empty();
      std::vector<char> touching(ne, 0);
      for (const auto& [f, g] : pairs)
        touching[static_cast<size_t>(element_of[f])] =
            touching[static_cast<size_t>(element_of[g])] = 1;
      for (size_t k = 0; k < ne; ++k) {
        if (!touching[k] || by_normal[k]) continue;
        all.V.middleRows(first[k], first[k + 1] - first[k]) =
            unoptimized.middleRows(first[k], first[k + 1] - first[k]);
        stale[k] = 1;
        ++stats.unoptimized_elements;
      }
      // Their pairs are found again after the fold repair, which moves some of them too.
      have_pairs = true;
    }
  } else {
    ScopedStageTimer timer(stats.times, "embedding");
    ScopedStageProgress shown(progress, "embedding");
    all.V = normal_displacement(quilt.base.V, quilt.base.F, shell_directions(quilt), points);
  }

  // The layout's versions of elements placed as even copies (SurfaceElement::through_layout),
  // embedded as the copies are (through the map where all their faces have a shell, else by
  // normal displacement): tried before such a copy is removed.
  std::vector<Eigen::Index> alternative_first(ne + 1, 0);
  for (size_t k = 0; k < ne; ++k)
    alternative_first[k + 1] =
        alternative_first[k] +
        static_cast<Eigen::Index>(quilt.elements[k].through_layout.face.size());
  MatrixX3d alternative_V;
  if (alternative_first.back() > 0 && options.remove_intersecting) {
    LocalCoordinates alt;
    const Eigen::Index na = alternative_first.back();
    alt.face.resize(na);
    alt.bary.resize(na, 3);
    alt.height.resize(na);
    std::vector<char> alt_normal(ne, map ? 0 : 1);
    for (size_t k = 0; k < ne; ++k) {
      const SurfaceElement::Alternative& a = quilt.elements[k].through_layout;
      for (size_t v = 0; v < a.face.size(); ++v) {
        const Eigen::Index i = alternative_first[k] + static_cast<Eigen::Index>(v);
        alt.face(i) = a.face[v];
        alt.bary.row(i) = a.barycentric.row(static_cast<Eigen::Index>(v));
        alt.height(i) = std::clamp(a.height(static_cast<Eigen::Index>(v)), 0.0, quilt.shell_height);
        if (map && map->shell_face(a.face[v]) < 0) alt_normal[k] = 1;
      }
    }
    alternative_V = normal_displacement(quilt.base.V, quilt.base.F, shell_directions(quilt), alt);
    if (map) {
      LocalCoordinates through = alt;
      for (size_t k = 0; k < ne; ++k)
        for (Eigen::Index i = alternative_first[k]; i < alternative_first[k + 1]; ++i)
          through.face(i) = alt_normal[k] ? 0 : map->shell_face(alt.face(i));
      const MatrixX3d mapped_alt = ShellEmbedding(*map).embed(through);
      for (size_t k = 0; k < ne; ++k)
        if (!alt_normal[k])
          alternative_V.middleRows(alternative_first[k],
                                   alternative_first[k + 1] - alternative_first[k]) =
              mapped_alt.middleRows(alternative_first[k],
                                    alternative_first[k + 1] - alternative_first[k]);
    }
  }

  // The check (issue 23): every vertex's signed height over the base as given. An element
  // under the base (the shell map of a base whose shell could only be made over a repaired
  // copy, say) is placed again by normal displacement; one still under it is removed at the
  // end. Elements moved by the repairs below are checked again before the output.
  PlacementCheckOptions check_options;
  check_options.height = quilt.shell_height;
  check_options.tolerance = stats.placement_tolerance;
  std::optional<SignedHeight> base_height;
  std::vector<ElementHeights> heights;
  std::vector<char> sunk(ne, 0);  // still under the base after the fallback: removed
  if (nv > 0) {
    ScopedStageTimer timer(stats.times, "placement check");
    ScopedStageProgress shown(progress, "placement check");
    base_height.emplace(quilt.input_base.V, quilt.input_base.F);
    heights = check_element_heights(*base_height, all.V, first, check_options);
    const PlacementFigures embedded = placement_figures(heights);
    stats.below_base_embedded = embedded.below_share();
    std::vector<char> again(ne, 0);
    for (size_t k = 0; k < ne; ++k)
      if (heights[k].below > 0) {
        if (by_normal[k])
          sunk[k] = 1;
        else
          again[k] = 1;
      }
    stats.replaced_below = static_cast<int>(std::count(again.begin(), again.end(), 1));
    if (stats.replaced_below > 0) {
      place_by_normal(quilt, points, first, again, all.V);
      const std::vector<ElementHeights> rechecked =
          check_element_heights(*base_height, all.V, first, check_options, again);
      for (size_t k = 0; k < ne; ++k)
        if (again[k]) {
          heights[k] = rechecked[k];
          sunk[k] = rechecked[k].below > 0;
          stale[k] = 1;
        }
      known_disjoint = false;
    }
  }
  // Elements to be removed for lying under the base take no part in the repairs: their face
  // pairs are forgotten.
  const bool any_sunk = std::find(sunk.begin(), sunk.end(), 1) != sunk.end();
  const auto forget_sunk = [&](std::vector<std::pair<int, int>>& p) {
    if (!any_sunk) return;
    p.erase(std::remove_if(p.begin(), p.end(),
                           [&](const std::pair<int, int>& q) {
                             return sunk[static_cast<size_t>(element_of[q.first])] ||
                                    sunk[static_cast<size_t>(element_of[q.second])];
                           }),
            p.end());
  };
  forget_sunk(pairs);
  // Elements moved after the check (rigid repair, ring separation, shrinking), checked again.
  std::vector<char> moved_after_check(ne, 0);

  // Elements the repairs pushed under the base (a folded element's flat shape fitted over a
  // curved base, a ring moved away from its neighbours: on the armor job 323 rings, up to
  // 0.43 H deep) are lifted out whole, after the fold repair (so that ring separation can part
  // the lifted rings from those they then touch) and after ring separation.
  // Returns which elements moved; their pairs are left to the caller's next update.
  const auto lift_moved = [&] {
    std::vector<char> lifted(ne, 0);
    if (heights.empty() ||
        std::find(moved_after_check.begin(), moved_after_check.end(), 1) == moved_after_check.end())
      return lifted;
    const std::vector<ElementHeights> rechecked =
        check_element_heights(*base_height, all.V, first, check_options, moved_after_check);
    std::vector<char> lift(ne, 0);
    for (size_t k = 0; k < ne; ++k)
      if (moved_after_check[k]) {
        heights[k] = rechecked[k];
        lift[k] = rechecked[k].below > 0 && !sunk[k];
      }
    std::fill(moved_after_check.begin(), moved_after_check.end(), 0);
    if (std::find(lift.begin(), lift.end(), 1) == lift.end()) return lifted;
    const std::vector<ElementHeights> after =
        lift_out_of_base(*base_height, all.V, first, check_options, lift, 4, &lifted);
    for (size_t k = 0; k < ne; ++k)
      if (lift[k]) heights[k] = after[k];
    stats.lifted_below += static_cast<int>(std::count(lifted.begin(), lifted.end(), 1));
    known_disjoint = false;
    return lifted;
  };

  // Repair (issue 13): an element the map folds through itself (over a sharp crease or next
  // to a cone of the parameterisation the map bends it too sharply) is replaced by its flat
  // shape moved by the similarity that best fits where the map put it (Umeyama): whole and
  // unfolded by construction, in its place and at its size.
  if (options.remove_intersecting) {
    ScopedStageTimer timer(stats.times, "fold repair");
    ScopedStageProgress shown(progress, "fold repair");
    if (!have_pairs && !known_disjoint) {
      pairs = all_face_pairs(all.V, all.F);
      forget_sunk(pairs);
      have_pairs = true;
    }
    // Folded: a pair within the element, or for an element moved since the pairs were found
    // (kept on the unoptimised map), its own test.
    std::vector<char> folded_now(ne, 0);
    for (const auto& [f, g] : pairs)
      if (element_of[f] == element_of[g] && !stale[static_cast<size_t>(element_of[f])])
        folded_now[static_cast<size_t>(element_of[f])] = 1;
    tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
      if (stale[k])
        folded_now[k] = !self_intersecting_components(
                             MatrixX3d(all.V.middleRows(first[k], first[k + 1] - first[k])),
                             quilt.elements[k].F)
                             .empty();
    });
    tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
      const SurfaceElement& e = quilt.elements[k];
      const Eigen::Index v0 = first[k], ev = first[k + 1] - first[k];
      if (!folded_now[k] || e.flat.rows() != ev) {
        folded_now[k] = 0;  // left as it is
        return;
      }
      const MatrixX3d placed = all.V.middleRows(v0, ev);
      const MatrixX3d rigid = similarity_fit(e.flat, placed);
      // As little rigidity as removes the fold: the mapped shape blended towards the fitted
      // flat one, the first blend without a self-intersection (the flat shape has none) that
      // stays out of the base (a flat ring fitted over a convex crease cuts into it: on the
      // armor job 226 of 276; the blends kept 95% and 90% mapped, tried first, bring that to
      // 160). Failing that, the first without a self-intersection, lifted out below.
      MatrixX3d best = rigid;
      bool found = false;
      const std::vector<Eigen::Index> whole = {0, ev};
      for (const double keep : {0.95, 0.9, 0.75, 0.5, 0.25, 0.0}) {
        MatrixX3d blend = keep * placed + (1 - keep) * rigid;
        if (keep > 0 && !self_intersecting_components(blend, e.F).empty()) continue;
        if (!found) {
          best = blend;
          found = true;
        }
        if (!base_height ||
            check_element_heights(*base_height, blend, whole, check_options)[0].below == 0) {
          best = std::move(blend);
          break;
        }
      }
      all.V.middleRows(v0, ev) = best;
    });
    for (size_t k = 0; k < ne; ++k) {
      stats.rigid_repairs += folded_now[k];
      stale[k] = stale[k] || folded_now[k];
      moved_after_check[k] = moved_after_check[k] || folded_now[k];
    }
    const std::vector<char> lifted = lift_moved();
    for (size_t k = 0; k < ne; ++k) stale[k] = stale[k] || lifted[k];
    if (have_pairs) {
      pairs = updated_pairs(quilt, all.V, all.F, element_of, std::move(pairs), stale);
      forget_sunk(pairs);
      std::fill(stale.begin(), stale.end(), 0);
    }
  }

  // Rings pressed into each other are moved apart whole, links kept (core/shell/ring_separation);
  // what still touches is left to the post-processing. Armor job: interior rings with the
  // swatch's 4 links 84.2 -> 91.3%, rings removed 122 -> 32.
  if (options.remove_intersecting && options.separate_rings && have_pairs) {
    ScopedStageTimer timer(stats.times, "ring separation");
    ScopedStageProgress shown(progress, "ring separation");
    std::vector<char> touching(ne, 0), folded_now(ne, 0);
    for (const auto& [f, g] : pairs) {
      if (element_of[f] == element_of[g])
        folded_now[static_cast<size_t>(element_of[f])] = 1;
      else
        touching[static_cast<size_t>(element_of[f])] =
            touching[static_cast<size_t>(element_of[g])] = 1;
    }
    for (size_t k = 0; k < ne; ++k) touching[k] = touching[k] && !folded_now[k];
    if (std::find(touching.begin(), touching.end(), 1) != touching.end()) {
      const ElementGrid grid(all.V, first, std::vector<char>(ne, 0));
      std::vector<char> near(ne, 0);
      for (size_t k = 0; k < ne; ++k)
        if (touching[k]) {
          near[k] = 1;
          for (const int j : grid.near(grid.box[k])) near[static_cast<size_t>(j)] = 1;
        }
      // Each ring binned on its flat shape (a ring the map bent keeps its cross sections).
      std::vector<std::optional<RingBins>> bins(ne), link_bins(ne);
      tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
        if (!near[k] || folded_now[k]) return;
        const SurfaceElement& e = quilt.elements[k];
        const Eigen::Index ev = static_cast<Eigen::Index>(e.face.size());
        const MatrixX3d placed = all.V.middleRows(first[k], ev);
        link_bins[k] = ring_loop_bins(placed, e.F);
        if (!link_bins[k]) return;
        bins[k] = e.flat.rows() == ev ? ring_loop_bins(e.flat, e.F) : link_bins[k];
      });
      const MatrixX3d before = all.V;
      RingSeparationStats sep;
      // Apart, but not into the base.
      RingSeparationOptions separation;
      separation.ground = &*base_height;
      std::vector<char> moved =
          separate_rings(all.V, first, bins, link_bins, touching, separation, &sep);
      stats.separation_left_shell =
          keep_in_shell(quilt, first, before, all.V, moved, *base_height, check_options);
      sep.moved -= stats.separation_left_shell;
      stats.separated_rings = sep.moved;
      stats.separation_reverted = sep.reverted;
      stats.separation_iterations = sep.iterations;
      for (size_t k = 0; k < ne; ++k) moved_after_check[k] = moved_after_check[k] || moved[k];
      const std::vector<char> lifted = lift_moved();
      for (size_t k = 0; k < ne; ++k) moved[k] = moved[k] || lifted[k];
      pairs = updated_pairs(quilt, all.V, all.F, element_of, std::move(pairs), moved);
      forget_sunk(pairs);
    }
  }

  // Post-processing (issue 13: no folded element reaches the output): an element that
  // intersects itself goes; of intersecting elements as few as can go (greedy_vertex_cover), and
  // those are tried again smaller (shrink_to_fit). Over the knight (armor job, before ring
  // separation) this kept 4 links on 80.4% of interior rings where dropping the later of each
  // pair kept 78.0%; after separation 32 rings are left to remove instead of 122.
  std::vector<char> drop(ne, 0), folded(ne, 0);
  if (options.remove_intersecting && !known_disjoint) {
    ScopedStageTimer timer(stats.times, "element removal");
    ScopedStageProgress shown(progress, "element removal");
    if (!have_pairs) {
      pairs = all_face_pairs(all.V, all.F);
      forget_sunk(pairs);
    }
    for (const auto& [f, g] : pairs)
      if (element_of[f] == element_of[g]) folded[element_of[f]] = drop[element_of[f]] = 1;
    std::vector<std::pair<int, int>> touching;
    for (const auto& [f, g] : pairs)
      if (element_of[f] != element_of[g]) touching.emplace_back(element_of[f], element_of[g]);
    greedy_vertex_cover(touching, drop);
    {
      // Folded and sunk elements are not tried again.
      std::vector<char> skip = folded;
      for (size_t k = 0; k < ne; ++k) skip[k] = skip[k] || sunk[k];
      const std::vector<char> back =
          try_alternatives(quilt, skip, alternative_V, alternative_first, all.V, drop);
      for (size_t k = 0; k < ne; ++k)
        if (back[k]) {
          moved_after_check[k] = 1;
          ++stats.layout_versions;
        }
    }
    if (options.shrink_to_fit) {
      // Sunk elements are not tried again (shrink_to_fit skips folded ones).
      std::vector<char> keep_out = folded;
      for (size_t k = 0; k < ne; ++k) keep_out[k] = keep_out[k] || sunk[k];
      const std::vector<char> dropped = drop;
      for (size_t k = 0; k < ne; ++k) drop[k] = drop[k] || sunk[k];
      stats.shrunk_to_fit = shrink_to_fit(quilt, keep_out, all.V, drop);
      for (size_t k = 0; k < ne; ++k)
        if (dropped[k] && !drop[k]) moved_after_check[k] = 1;
    }
  }
  // The last word of the check: elements moved since are measured again, and every element
  // still under the base is removed; the output's figures.
  if (!heights.empty()) {
    ScopedStageTimer timer(stats.times, "placement check");
    ScopedStageProgress shown(progress, "placement check");
    for (size_t k = 0; k < ne; ++k) moved_after_check[k] = moved_after_check[k] && !drop[k];
    if (std::find(moved_after_check.begin(), moved_after_check.end(), 1) !=
        moved_after_check.end()) {
      const std::vector<ElementHeights> rechecked =
          check_element_heights(*base_height, all.V, first, check_options, moved_after_check);
      for (size_t k = 0; k < ne; ++k)
        if (moved_after_check[k]) heights[k] = rechecked[k];
    }
    std::vector<char> kept(ne, 0);
    for (size_t k = 0; k < ne; ++k) {
      if (!drop[k] && (sunk[k] || heights[k].below > 0)) {
        drop[k] = 1;
        sunk[k] = 1;
      }
      kept[k] = !drop[k];
    }
    const PlacementFigures output = placement_figures(heights, kept);
    stats.checked_vertices = output.vertices;
    stats.below_base = output.below_share();
    stats.above_shell = output.above_share();
    stats.lowest_height = output.lowest / quilt.shell_height;
  }
  TriMesh out;
  out.kinds = quilt.kinds;
  std::vector<double> areas;
  {
    Eigen::Index kv = 0, kf = 0, v0 = 0, f0 = 0;
    for (size_t k = 0; k < quilt.elements.size(); ++k) {
      const Eigen::Index ev = static_cast<Eigen::Index>(quilt.elements[k].face.size());
      const Eigen::Index ef = quilt.elements[k].F.rows();
      if (!drop[k]) {
        kv += ev;
        kf += ef;
      }
      v0 += ev;
      f0 += ef;
    }
    out.V.resize(kv, 3);
    out.F.resize(kf, 3);
    kv = kf = v0 = f0 = 0;
    for (size_t k = 0; k < quilt.elements.size(); ++k) {
      const SurfaceElement& e = quilt.elements[k];
      const Eigen::Index ev = static_cast<Eigen::Index>(e.face.size()), ef = e.F.rows();
      if (drop[k]) {
        ++(sunk[k]     ? stats.removed_below
           : folded[k] ? stats.removed_self_intersecting
                       : stats.removed_intersecting);
      } else {
        out.V.middleRows(kv, ev) = all.V.middleRows(v0, ev);
        out.F.middleRows(kf, ef) = e.F.array() + static_cast<int>(kv);
        out.face_kind.insert(out.face_kind.end(), static_cast<size_t>(ef), e.kind);
        areas.push_back(face_areas(all.V.middleRows(v0, ev), e.F).sum());
        kv += ev;
        kf += ef;
      }
      v0 += ev;
      f0 += ef;
    }
  }
  stats.faces = out.num_faces();
  stats.vertices = out.num_vertices();
  stats.elements = static_cast<int>(areas.size());
  if (!areas.empty()) {
    double mean = 0, var = 0;
    for (const double a : areas) mean += a;
    mean /= static_cast<double>(areas.size());
    for (const double a : areas) var += (a - mean) * (a - mean);
    var /= static_cast<double>(areas.size());
    stats.element_area_mean = mean;
    stats.element_area_cv = mean > 0 ? std::sqrt(var) / mean : 0;
    stats.element_area_min = *std::min_element(areas.begin(), areas.end());
    stats.element_area_max = *std::max_element(areas.begin(), areas.end());
  }
  {
    ScopedStageTimer timer(stats.times, "coverage");
    ScopedStageProgress shown(progress, "coverage");
    // Sampled at the refined base's face centroids (edges at most 0.3 of the swatch side): the
    // input's faces can be far larger than the swatch (the brick wall's 84 faces made the
    // figure jump by 0.2 between runs of nearly identical output).
    // Only geometry on the base's outer side counts (issue 23: texture inside the base
    // covered the open quadruped's legs from within).
    stats.coverage =
        surface_coverage(quilt.base, out, 1.5 * quilt.shell_height,
                         stats.placement_tolerance * quilt.shell_height, options.coverage_faces);
  }
  if (stats_out) *stats_out = std::move(stats);
  return out;
}

}  // namespace mq
