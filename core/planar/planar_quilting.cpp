#include "core/planar/planar_quilting.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "core/common/errors.h"
#include "core/mesh/embree_device.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/patch_quilting.h"
#include "core/planar/swatch_density.h"
#include "core/planar/swatch_symmetry.h"
#include "core/planar/synthesis_grid.h"

namespace mq {

namespace {

// The growing output: elements with a per-cell index of their footprints for local queries.
class OutputStore final : public PatchOutput {
 public:
  explicit OutputStore(const SynthesisGrid& grid) : grid_(grid), cells_(grid.num_cells()) {}

  const Element& element(int id) const override { return elements_[id]; }
  std::vector<int> elements_near(const Vector2d& lo, const Vector2d& hi) const override {
    return query(lo, hi);
  }
  int add(Element e) override {
    const int id = static_cast<int>(elements_.size());
    elements_.push_back(std::move(e));
    alive_.push_back(1);
    index(id);
    return id;
  }
  void replace(int id, Element e) override {
    elements_[id] = std::move(e);
    index(id);
  }
  void remove(int id) override { alive_[id] = 0; }
  bool alive(int id) const override { return alive_[id] != 0; }
  const Element& operator[](int id) const { return elements_[id]; }
  const std::vector<Element>& elements() const { return elements_; }
  int size() const { return static_cast<int>(elements_.size()); }

  // Alive elements whose footprint box meets [lo, hi], ascending ids.
  std::vector<int> query(const Vector2d& lo, const Vector2d& hi) const {
    std::vector<int> ids;
    const Cell a = clamp(grid_.cell_of(lo.x(), lo.y())), b = clamp(grid_.cell_of(hi.x(), hi.y()));
    for (int y = a.y; y <= b.y; ++y)
      for (int x = a.x; x <= b.x; ++x)
        for (const int id : cells_[grid_.index({x, y})]) ids.push_back(id);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    std::vector<int> result;
    for (const int id : ids) {
      const Element& e = elements_[id];
      if (alive_[id] && e.lo.x() <= hi.x() && e.hi.x() >= lo.x() && e.lo.y() <= hi.y() &&
          e.hi.y() >= lo.y())
        result.push_back(id);
    }
    return result;
  }

 private:
  Cell clamp(Cell c) const {
    return {std::clamp(c.x, 0, grid_.nx() - 1), std::clamp(c.y, 0, grid_.ny() - 1)};
  }
  void index(int id) {
    const Element& e = elements_[id];
    const Cell a = clamp(grid_.cell_of(e.lo.x(), e.lo.y()));
    const Cell b = clamp(grid_.cell_of(e.hi.x(), e.hi.y()));
    for (int y = a.y; y <= b.y; ++y)
      for (int x = a.x; x <= b.x; ++x) {
        auto& list = cells_[grid_.index({x, y})];
        if (list.empty() || list.back() != id) list.push_back(id);
      }
  }

  const SynthesisGrid& grid_;
  std::vector<Element> elements_;
  std::vector<unsigned char> alive_;
  std::vector<std::vector<int>> cells_;
};

// The checks of the options against the swatch: some element fits the domain, and the output
// is not estimated too large to make.
void check_against_swatch(const PreparedSwatch& s, const PlanarQuiltingOptions& o) {
  double smallest = std::numeric_limits<double>::infinity();
  for (const Element& e : s.elements)
    smallest = std::min(smallest, std::max(e.hi.x() - e.lo.x(), e.hi.y() - e.lo.y()));
  MQ_CHECK(smallest <= std::max(o.length, o.width), InvalidInput,
           "every element of the swatch is larger than the requested ", o.length, " x ", o.width,
           " domain (smallest element spans ", smallest, ")");
  // Output size estimate, to refuse jobs that cannot fit before any work.
  const double faces = estimated_plane_faces(s, o.length, o.width);
  MQ_CHECK(faces <= o.max_faces, InvalidInput, "a ", o.length, " x ", o.width,
           " layer of this swatch would have about ", std::round(faces),
           " faces, more than the limit of ", o.max_faces, " (--max-faces); choose a smaller size");
}

// The grid cell (section 2.3): given or matching_cell_size's. The grid and the swatch in cells
// bound the memory of the grid and the offsets each match searches (every swatch cell is a
// candidate offset): the default cell gives at most a few hundred thousand and a few hundred.
double grid_cell(const PreparedSwatch& swatch, const PlanarQuiltingOptions& options) {
  const double cell = options.cell_size > 0 ? options.cell_size : matching_cell_size(swatch);
  MQ_CHECK(cell <= std::min(swatch.size.x(), swatch.size.y()), InvalidInput, "the cell size ", cell,
           " is larger than the swatch's footprint");
  const double cells_estimate = std::ceil(options.length / cell) * std::ceil(options.width / cell);
  MQ_CHECK(cells_estimate <= double(1 << 24), InvalidInput, "the grid would have ", cells_estimate,
           " cells of size ", cell, " (at most ", 1 << 24, "); use a larger --cell");
  const double swatch_cells =
      std::floor(swatch.size.x() / cell) * std::floor(swatch.size.y() / cell);
  MQ_CHECK(swatch_cells <= double(1 << 16), InvalidInput, "a cell of ", cell,
           " divides the swatch into ", swatch_cells, " cells (at most ", 1 << 16,
           "), too many offsets to match; use a larger --cell");
  return cell;
}

// One run of planar quilting (section 2): the grid of cells, the swatch's queries and the
// growing output, patch by patch from the first at the origin.
class PlaneQuilter {
 public:
  PlaneQuilter(const PreparedSwatch& swatch, const PlanarQuiltingOptions& options, double cell,
               TranslationCostEvaluator& evaluator, PlanarQuiltingStats& stats)
      : swatch_(swatch),
        options_(options),
        cell_(cell),
        evaluator_(evaluator),
        stats_(stats),
        grid_(Vector2d::Zero(), cell, static_cast<int>(std::ceil(options.length / cell)),
              static_cast<int>(std::ceil(options.width / cell))),
        domain_hi_(options.length, options.width),
        output_(grid_),
        rng_(options.seed) {
    stats.cell_size = cell;
    stats.grid_nx = grid_.nx();
    stats.grid_ny = grid_.ny();
    patch_options_.correspondence = options.correspondence;
    patch_options_.merging = options.merging;
    patch_options_.merging.pieces_beyond = true;  // the grid marks whole patches (see there)
    patch_options_.deform = options.deform;
    in_domain_ = [this](const Element& e) {
      return e.hi.x() > domain_lo_.x() && e.lo.x() < domain_hi_.x() && e.hi.y() > domain_lo_.y() &&
             e.lo.y() < domain_hi_.y();
    };
  }

  SynthesisGrid& grid() { return grid_; }

  // The swatch's face tree and Laplacian topologies, and the side of the matched sub-patch.
  void prepare_queries() {
    const int cells_x = static_cast<int>(std::floor(swatch_.size.x() / cell_ + 1e-9));
    const int cells_y = static_cast<int>(std::floor(swatch_.size.y() / cell_ + 1e-9));
    window_ = std::max(
        1, std::min({static_cast<int>(options_.subpatch_fraction * std::min(cells_x, cells_y)),
                     cells_x, cells_y}));
    ScopedStageTimer timer(stats_.times, Stage::Prepare);
    swatch_tree_ = std::make_unique<SwatchFaceTree>(swatch_.mesh.V, swatch_.mesh.F);
    laplacians_ = swatch_topologies(swatch_);
    // The swatch must be able to shift by a period of its texture and still cover the
    // sub-patch, or no placement continues a lattice: the range of offsets (swatch cells minus
    // window) is kept at least a period along each axis. Half the 3 x 3 chain mail sheet left
    // 2.37 of its 2.5 period along x: a 20 x 20 plane had 93% of interior rings with their 4
    // links, 100% with this bound.
    const Vector2d period = axis_periods(swatch_, *swatch_tree_, cell_);
    for (int axis = 0; axis < 2; ++axis) {
      if (!(period(axis) > 0)) continue;
      const int cells = axis == 0 ? cells_x : cells_y;
      window_ = std::max(
          1, std::min(window_, cells - static_cast<int>(std::ceil(period(axis) / cell_ - 1e-9))));
    }
    stats_.window_cells = window_;
  }

  // First patch: the swatch as it is, at the origin.
  void place_first_patch() {
    ScopedStageTimer timer(stats_.times, Stage::Merging);
    for (const Element& e : swatch_.elements)
      if (in_domain_(e)) {
        output_.add(e);
        ++stats_.counts.added;
      }
    mark_patch(Vector2d::Zero(), swatch_.size.head<2>());
    stats_.iterations = 1;
  }

  // One patch at a seed cell: step 2 (section 2.4) places the swatch, steps 3-5 (sections
  // 2.5-2.7) merge it.
  void quilt_at(const Cell& seed) {
    ++stats_.iterations;
    const Vector3d t = match_at(seed);
    const Vector2d patch_lo = t.head<2>(), patch_hi = patch_lo + swatch_.size.head<2>();
    const OverlapRegion region(patch_lo, patch_hi, grid_.processed_snapshot());
    const SwatchQueries queries{*swatch_tree_, embree_, laplacians_};
    quilt_patch(output_, swatch_, queries, t, region, in_domain_, patch_options_, stats_.counts,
                stats_.times);
    mark_patch(patch_lo, patch_hi);
    grid_.set_processed(seed);  // progress is guaranteed even if the patch is clipped
  }

  // Post-processing: elements outside the domain go; border elements stay whole unless
  // trimmed (into `trimmed`, which the result points into).
  std::vector<const Element*> keep_in_domain(std::vector<Element>& trimmed) {
    ScopedStageTimer timer(stats_.times, Stage::PostProcessing);
    std::vector<const Element*> kept;
    trimmed.reserve(output_.size());
    for (int id = 0; id < output_.size(); ++id) {
      if (!output_.alive(id)) continue;
      const Element& e = output_[id];
      if (!in_domain_(e)) {
        ++stats_.removed_post;
        continue;
      }
      const bool crosses = e.lo.x() < domain_lo_.x() || e.lo.y() < domain_lo_.y() ||
                           e.hi.x() > domain_hi_.x() || e.hi.y() > domain_hi_.y();
      if (options_.trim_border && crosses) {
        trimmed.push_back(trimmed_to_domain(e));
        ++stats_.trimmed;
        continue;
      }
      kept.push_back(&e);
    }
    for (const Element& e : trimmed) kept.push_back(&e);
    return kept;
  }

 private:
  // Step 2 (section 2.4): the sub-patch around the seed, the admissible offsets and the one
  // chosen among the cheapest.
  Vector3d match_at(const Cell& seed) {
    const int half = window_ / 2;
    const int px0 = std::max(0, std::min(seed.x - half, grid_.nx() - window_));
    const int py0 = std::max(0, std::min(seed.y - half, grid_.ny() - window_));
    const int px1 = std::min(grid_.nx(), px0 + window_) - 1,
              py1 = std::min(grid_.ny(), py0 + window_) - 1;
    const Vector2d sub_lo(px0 * cell_, py0 * cell_), sub_hi((px1 + 1) * cell_, (py1 + 1) * cell_);
    const Vector2d t_min = sub_hi - swatch_.size.head<2>();
    const Vector2d& t_max = sub_lo;
    ScopedStageTimer timer(stats_.times, Stage::Matching);
    std::vector<const Element*> near;
    for (const int id : output_.query(sub_lo, sub_hi)) near.push_back(&output_[id]);
    MatrixX3d P, NP;
    gather_subpatch(near, sub_lo, sub_hi, options_.match_points, P, NP);
    const MatrixX3d T = whole_cell_offsets(t_min, t_max, cell_);
    MatchingOptions matching = options_.matching;
    matching.lambda = options_.matching.lambda / cell_;  // distances in cells (scale invariant)
    const OffsetChoice choice =
        choose_offset(*swatch_tree_, evaluator_, P, NP, T, t_min, t_max, cell_, matching, rng_);
    stats_.matched_point_offsets += choice.point_offsets;
    return choice.offset;
  }

  // Marks the cells lying entirely inside the patch footprint [lo, hi].
  void mark_patch(const Vector2d& lo, const Vector2d& hi) {
    const int x0 = std::max(0, static_cast<int>(std::ceil(lo.x() / cell_ - 1e-9)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(lo.y() / cell_ - 1e-9)));
    const int x1 = std::min(grid_.nx(), static_cast<int>(std::floor(hi.x() / cell_ + 1e-9)));
    const int y1 = std::min(grid_.ny(), static_cast<int>(std::floor(hi.y() / cell_ + 1e-9)));
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) grid_.set_processed({x, y});
  }

  // The faces of e whose centroids lie in the domain, as an element of its own.
  Element trimmed_to_domain(const Element& e) const {
    std::vector<int> faces;
    for (int f = 0; f < e.F.rows(); ++f) {
      const Vector3d c =
          (e.V.row(e.F(f, 0)) + e.V.row(e.F(f, 1)) + e.V.row(e.F(f, 2))).transpose() / 3.0;
      if (c.x() >= domain_lo_.x() && c.y() >= domain_lo_.y() && c.x() <= domain_hi_.x() &&
          c.y() <= domain_hi_.y())
        faces.push_back(f);
    }
    return element_part(e, faces);
  }

  const PreparedSwatch& swatch_;
  const PlanarQuiltingOptions& options_;
  const double cell_;
  TranslationCostEvaluator& evaluator_;
  PlanarQuiltingStats& stats_;
  SynthesisGrid grid_;
  const Vector2d domain_lo_ = Vector2d::Zero(), domain_hi_;
  int window_ = 1;  // side of the matched sub-patch, in cells
  std::unique_ptr<SwatchFaceTree> swatch_tree_;
  const EmbreeDevice embree_;  // for the merging's temporary BVHs
  LaplacianTopologyCache laplacians_;
  OutputStore output_;
  std::mt19937_64 rng_;
  PatchQuiltingOptions patch_options_;
  std::function<bool(const Element&)> in_domain_;
};

}  // namespace

void PlanarQuiltingOptions::validate() const {
  MQ_CHECK(std::isfinite(length) && std::isfinite(width) && length > 0 && width > 0, InvalidInput,
           "the output size must be positive and finite, got ", length, " x ", width);
  MQ_CHECK(cell_size == 0 || (std::isfinite(cell_size) && cell_size > 0), InvalidInput,
           "the cell size must be positive, got ", cell_size);
  MQ_CHECK(subpatch_fraction > 0 && subpatch_fraction <= 1, InvalidInput,
           "the sub-patch fraction must lie in (0, 1], got ", subpatch_fraction);
}

double estimated_plane_faces(const PreparedSwatch& swatch, double length, double width) {
  const SwatchFaceDensity d = swatch_face_density(swatch);
  const double sx = swatch.size.x(), sy = swatch.size.y();
  const double L = std::max(length, sx), W = std::max(width, sy);
  // Elements crossing the border are kept whole: a thread runs on past it, by a quarter of a
  // swatch thread over both ends of its track, about (the faces written, 12 x 12 to 36 x 36:
  // 0.85-1.01 of the estimate without it; 0.95-1.05 with it on the wire job and the 4 x 4
  // weave). A compact element's overhang is within the estimate's rounding.
  return d.compact * L * W + d.along_x * (L + sx / 4) * W + d.along_y * L * (W + sy / 4);
}

double matching_cell_size(const PreparedSwatch& s) {
  // Half an element across, but at least 8 cells along the swatch's shorter side so the
  // sub-patch and the offsets have room.
  const double shorter = std::min(s.size.x(), s.size.y());
  return std::min(0.5 * s.mean_element_diameter, shorter / 8.0);
}

TriMesh quilt_plane(const TriMesh& swatch_mesh, const PlanarQuiltingOptions& options,
                    TranslationCostEvaluator& evaluator, PlanarQuiltingStats* stats_out,
                    ProgressSink* progress, PlaneSources* sources) {
  PlanarQuiltingStats stats;
  PreparedSwatch swatch;
  {
    ScopedStageTimer timer(stats.times, Stage::Prepare);
    swatch = prepare_swatch(swatch_mesh);
    if (sources) track_sources(swatch);
    // After the swatch, so that a bad swatch is what a job with both wrong is refused for.
    options.validate();
    check_against_swatch(swatch, options);
  }
  PlaneQuilter quilter(swatch, options, grid_cell(swatch, options), evaluator, stats);
  quilter.prepare_queries();
  quilter.place_first_patch();
  SynthesisGrid& grid = quilter.grid();
  report_progress(progress, Stage::Quilting, grid.num_processed(), grid.num_cells());
  Cell seed;
  while (grid.next_seed(seed)) {
    quilter.quilt_at(seed);
    report_progress(progress, Stage::Quilting, grid.num_processed(), grid.num_cells());
  }
  std::vector<Element> trimmed;
  const std::vector<const Element*> kept = quilter.keep_in_domain(trimmed);
  TriMesh result = merge_elements(kept);
  result.kinds = swatch.kinds;
  if (sources) {
    sources->point.resize(result.num_vertices(), 3);
    sources->element.clear();
    sources->element_vertices.clear();
    sources->element_faces.clear();
    Eigen::Index row = 0;
    for (const Element* e : kept) {
      MQ_CHECK(e->source.rows() == e->V.rows() &&
                   e->source_element.size() == static_cast<size_t>(e->V.rows()),
               InternalError, "planar quilting: an element lost its sources");
      sources->point.middleRows(row, e->V.rows()) = e->source;
      sources->element.insert(sources->element.end(), e->source_element.begin(),
                              e->source_element.end());
      sources->element_vertices.push_back(static_cast<int>(e->V.rows()));
      sources->element_faces.push_back(static_cast<int>(e->F.rows()));
      row += e->V.rows();
    }
  }
  // Back to the swatch's own axes (the thickness axis returns to where it was).
  const Eigen::Matrix3d back = swatch.rotation.transpose();
  result.V = (result.V * back.transpose()).eval();
  result.N = (result.N * back.transpose()).eval();
  report_progress(progress, Stage::Quilting, 1, 1);
  stats.faces = result.num_faces();
  stats.vertices = result.num_vertices();
  stats.elements = static_cast<int>(kept.size());
  if (stats_out) *stats_out = std::move(stats);
  return result;
}

}  // namespace mq
