#include "core/planar_quilting.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "core/closest_point_query.h"
#include "core/errors.h"
#include "core/laplacian_deformation.h"
#include "core/mesh_intersections.h"
#include "core/mesh_topology.h"
#include "core/synthesis_grid.h"

namespace mq {

namespace {

TriMesh as_mesh(const Element& e) {
  TriMesh m;
  m.V = e.V;
  m.F = e.F;
  return m;
}

bool boxes_overlap(const Element& a, const Element& b) {
  return a.lo.x() <= b.hi.x() && b.lo.x() <= a.hi.x() && a.lo.y() <= b.hi.y() &&
         b.lo.y() <= a.hi.y() && a.z_lo <= b.z_hi && b.z_lo <= a.z_hi;
}

// The growing output: elements with a per-cell index of their footprints for local queries.
class OutputStore {
 public:
  explicit OutputStore(const SynthesisGrid& grid) : grid_(grid), cells_(grid.num_cells()) {}

  int add(Element e) {
    const int id = static_cast<int>(elements_.size());
    elements_.push_back(std::move(e));
    alive_.push_back(1);
    index(id);
    return id;
  }
  void replace(int id, Element e) {
    elements_[id] = std::move(e);
    index(id);
  }
  void remove(int id) { alive_[id] = 0; }
  bool alive(int id) const { return alive_[id] != 0; }
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

double auto_cell_size(const PreparedSwatch& s) {
  // Half an element across, but at least 8 cells along the swatch's shorter side so the
  // sub-patch and the offsets have room.
  const double shorter = std::min(s.size.x(), s.size.y());
  return std::min(0.5 * s.mean_element_diameter, shorter / 8.0);
}

void validate(const PreparedSwatch& s, const PlanarQuiltingOptions& o) {
  MQ_CHECK(std::isfinite(o.length) && std::isfinite(o.width) && o.length > 0 && o.width > 0,
           InvalidInput, "the output size must be positive and finite, got ", o.length, " x ",
           o.width);
  MQ_CHECK(o.cell_size == 0 || (std::isfinite(o.cell_size) && o.cell_size > 0), InvalidInput,
           "the cell size must be positive, got ", o.cell_size);
  MQ_CHECK(o.subpatch_fraction > 0 && o.subpatch_fraction <= 1, InvalidInput,
           "the sub-patch fraction must lie in (0, 1], got ", o.subpatch_fraction);
  double smallest = std::numeric_limits<double>::infinity();
  for (const Element& e : s.elements)
    smallest = std::min(smallest, std::max(e.hi.x() - e.lo.x(), e.hi.y() - e.lo.y()));
  MQ_CHECK(smallest <= std::max(o.length, o.width), InvalidInput,
           "every element of the swatch is larger than the requested ", o.length, " x ", o.width,
           " domain (smallest element spans ", smallest, ")");
  // Output size estimate from the swatch's face density, to refuse jobs that cannot fit.
  const double faces = static_cast<double>(s.mesh.F.rows()) * o.length * o.width /
                       (s.size.x() * s.size.y());
  MQ_CHECK(faces < 2e8, InvalidInput, "a ", o.length, " x ", o.width,
           " layer of this swatch would have about ", faces,
           " faces, more than this tool can hold; choose a smaller size");
}

}  // namespace

TriMesh quilt_plane(const TriMesh& swatch_mesh, const PlanarQuiltingOptions& options,
                    TranslationCostEvaluator& evaluator, PlanarQuiltingStats* stats_out,
                    ProgressSink* progress) {
  PlanarQuiltingStats stats;
  StageTimes& times = stats.times;
  PreparedSwatch swatch;
  {
    ScopedStageTimer timer(times, "prepare");
    swatch = prepare_swatch(swatch_mesh);
    validate(swatch, options);
  }
  const double cell = options.cell_size > 0 ? options.cell_size : auto_cell_size(swatch);
  MQ_CHECK(cell <= std::min(swatch.size.x(), swatch.size.y()), InvalidInput, "the cell size ",
           cell, " is larger than the swatch's footprint");
  const double cells_estimate = std::ceil(options.length / cell) * std::ceil(options.width / cell);
  MQ_CHECK(cells_estimate <= double(1 << 26), InvalidInput, "the grid would have ",
           cells_estimate, " cells; use a larger --cell");
  SynthesisGrid grid(Vector2d::Zero(), cell, static_cast<int>(std::ceil(options.length / cell)),
                     static_cast<int>(std::ceil(options.width / cell)));
  stats.cell_size = cell;
  stats.grid_nx = grid.nx();
  stats.grid_ny = grid.ny();
  const int swatch_cells_x = static_cast<int>(std::floor(swatch.size.x() / cell + 1e-9));
  const int swatch_cells_y = static_cast<int>(std::floor(swatch.size.y() / cell + 1e-9));
  const int window = std::max(
      1, std::min({static_cast<int>(options.subpatch_fraction * std::min(swatch_cells_x,
                                                                          swatch_cells_y)),
                   swatch_cells_x, swatch_cells_y}));
  const double mean_edge = swatch.mean_edge_length;
  const Vector2d domain_lo(0, 0), domain_hi(options.length, options.width);

  std::unique_ptr<SwatchDistanceGrid> distance_grid;
  std::unique_ptr<ClosestPointQuery> swatch_query;
  {
    ScopedStageTimer timer(times, "prepare");
    distance_grid = std::make_unique<SwatchDistanceGrid>(swatch.mesh.V, swatch.mesh.F);
    swatch_query = std::make_unique<ClosestPointQuery>(swatch.mesh.V, swatch.mesh.F);
  }
  OutputStore output(grid);
  std::mt19937_64 rng(options.seed);

  // Adds e unless it would intersect a live output element other than those in `ignore`.
  auto fits = [&](const Element& e, const std::vector<int>& ignore) {
    const TriMesh m = as_mesh(e);
    for (const int id : output.query(e.lo, e.hi)) {
      if (std::find(ignore.begin(), ignore.end(), id) != ignore.end()) continue;
      if (boxes_overlap(output[id], e) && meshes_intersect(as_mesh(output[id]), m)) return false;
    }
    return true;
  };
  auto in_domain = [&](const Element& e) {
    return e.hi.x() > domain_lo.x() && e.lo.x() < domain_hi.x() && e.hi.y() > domain_lo.y() &&
           e.lo.y() < domain_hi.y();
  };
  // Marks the cells lying entirely inside the patch footprint [lo, hi].
  auto mark_patch = [&](const Vector2d& lo, const Vector2d& hi) {
    const int x0 = std::max(0, static_cast<int>(std::ceil(lo.x() / cell - 1e-9)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(lo.y() / cell - 1e-9)));
    const int x1 = std::min(grid.nx(), static_cast<int>(std::floor(hi.x() / cell + 1e-9)));
    const int y1 = std::min(grid.ny(), static_cast<int>(std::floor(hi.y() / cell + 1e-9)));
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) grid.set_processed({x, y});
  };

  // First patch: the swatch as it is, at the origin.
  {
    ScopedStageTimer timer(times, "merging");
    for (const Element& e : swatch.elements)
      if (in_domain(e)) {
        output.add(e);
        ++stats.elements_added;
      }
    mark_patch(Vector2d::Zero(), swatch.size.head<2>());
    stats.iterations = 1;
  }
  report_progress(progress, "quilting", grid.num_processed(), grid.num_cells());

  Cell seed;
  while (grid.next_seed(seed)) {
    ++stats.iterations;
    // Step 2 (section 2.4): the sub-patch around the seed and the admissible offsets.
    const int half = window / 2;
    const int px0 = std::max(0, std::min(seed.x - half, grid.nx() - window));
    const int py0 = std::max(0, std::min(seed.y - half, grid.ny() - window));
    const int px1 = std::min(grid.nx(), px0 + window) - 1, py1 = std::min(grid.ny(), py0 + window) - 1;
    const Vector2d sub_lo(px0 * cell, py0 * cell), sub_hi((px1 + 1) * cell, (py1 + 1) * cell);
    const Vector2d t_min = sub_hi - swatch.size.head<2>(), t_max = sub_lo;
    OffsetChoice choice;
    {
      ScopedStageTimer timer(times, "matching");
      std::vector<Vector3d> points, normals;
      for (const int id : output.query(sub_lo, sub_hi)) {
        const Element& e = output[id];
        for (int v = 0; v < e.V.rows(); ++v) {
          const double x = e.V(v, 0), y = e.V(v, 1);
          if (x >= sub_lo.x() && x <= sub_hi.x() && y >= sub_lo.y() && y <= sub_hi.y()) {
            points.push_back(e.V.row(v).transpose());
            normals.push_back(e.N.row(v).transpose());
          }
        }
      }
      const size_t n = options.match_points > 0
                           ? std::min(points.size(), static_cast<size_t>(options.match_points))
                           : points.size();
      MatrixX3d P(n, 3), NP(n, 3);
      for (size_t i = 0; i < n; ++i) {
        const size_t k = i * points.size() / n;
        P.row(i) = points[k].transpose();
        NP.row(i) = normals[k].transpose();
      }
      const int kx0 = static_cast<int>(std::ceil(t_min.x() / cell - 1e-9));
      const int ky0 = static_cast<int>(std::ceil(t_min.y() / cell - 1e-9));
      const int kx1 = static_cast<int>(std::floor(t_max.x() / cell + 1e-9));
      const int ky1 = static_cast<int>(std::floor(t_max.y() / cell + 1e-9));
      std::vector<Vector3d> offsets;
      for (int ky = ky0; ky <= ky1; ++ky)
        for (int kx = kx0; kx <= kx1; ++kx) offsets.emplace_back(kx * cell, ky * cell, 0.0);
      if (offsets.empty()) offsets.emplace_back(t_max.x(), t_max.y(), 0.0);
      MatrixX3d T(offsets.size(), 3);
      for (size_t i = 0; i < offsets.size(); ++i) T.row(i) = offsets[i].transpose();
      MatchingOptions matching = options.matching;
      matching.lambda = options.matching.lambda / cell;  // distances in cells (scale invariant)
      choice = choose_offset(*distance_grid, evaluator, P, NP, T, t_min, t_max, cell, matching,
                             rng);
      stats.matched_point_offsets += choice.point_offsets;
    }
    const Vector3d t = choice.offset;
    const Vector2d patch_lo = t.head<2>(), patch_hi = patch_lo + swatch.size.head<2>();
    const OverlapRegion region(grid, patch_lo, patch_hi);

    // Step 3 (section 2.5): correspondences in the overlapping region.
    Correspondences corr;
    std::vector<Element> moved(swatch.elements.size());
    {
      ScopedStageTimer timer(times, "correspondence");
      for (size_t i = 0; i < moved.size(); ++i) {
        moved[i] = swatch.elements[i];
        moved[i].translate(t);
      }
      corr = find_correspondences(output.elements(), output.query(patch_lo, patch_hi), region,
                                  swatch, *swatch_query, t, options.correspondence);
      stats.pairs += static_cast<int>(corr.pairs.size());
      stats.relations += static_cast<int>(corr.relations.size());
    }

    // Step 4 (section 2.6): deform both sides of every relation towards the averaged points.
    std::map<int, Element> deformed_out;  // output id -> deformed copy
    {
      ScopedStageTimer timer(times, "deformation");
      std::map<int, std::vector<LinearConstraint>> out_constraints, in_constraints;
      for (const VertexFacePair& p : corr.pairs) {
        const Vector3d v = output[p.out_element].V.row(p.out_vertex).transpose();
        const Vector3d target = 0.5 * (v + p.closest);
        out_constraints[p.out_element].push_back(LinearConstraint::point(p.out_vertex, target));
        const auto& f = swatch.elements[p.in_element].F.row(p.in_face);
        in_constraints[p.in_element].push_back(
            LinearConstraint::barycentric(f(0), f(1), f(2), p.barycentric, target));
      }
      if (options.deform) {
        std::vector<DeformationJob> jobs;
        std::vector<std::pair<bool, int>> owners;  // (is output, id)
        // Section 2.6 aligns elements where they correspond; the rest of a long element (a
        // thread running far out of the overlap) is anchored so it does not swing.
        auto anchored = [&](const Element& e, std::vector<LinearConstraint> cs) {
          const auto anchors =
              anchor_far_vertices(e.V, e.F, cs, options.merging.deformation_rings);
          cs.insert(cs.end(), anchors.begin(), anchors.end());
          return cs;
        };
        for (auto& [id, cs] : out_constraints) {
          jobs.push_back({&output[id].V, &output[id].F, anchored(output[id], std::move(cs))});
          owners.emplace_back(true, id);
        }
        for (auto& [id, cs] : in_constraints) {
          jobs.push_back({&moved[id].V, &moved[id].F, anchored(moved[id], std::move(cs))});
          owners.emplace_back(false, id);
        }
        DeformationOptions d;
        d.mu = options.merging.mu;
        std::vector<MatrixX3d> solved = deform_elements(jobs, d);
        for (size_t j = 0; j < solved.size(); ++j) {
          const auto [is_out, id] = owners[j];
          Element& e = is_out ? deformed_out[id] : moved[id];
          if (is_out) {
            e.F = output[id].F;
          }
          e.V = std::move(solved[j]);
          e.update();
        }
      }
    }

    // Step 5 (section 2.7): merge.
    {
      ScopedStageTimer timer(times, "merging");
      // Partners of each swatch element. Relations carried by only a few pairs next to a strong
      // one come from elements that merely touch it (crossing threads of a weave, neighbouring
      // rings): they are not the same element and are ignored.
      std::map<std::pair<int, int>, int> pair_count;
      for (const VertexFacePair& p : corr.pairs) ++pair_count[{p.out_element, p.in_element}];
      std::vector<int> strongest(moved.size(), 0);
      for (const auto& [rel, n] : pair_count) strongest[rel.second] = std::max(strongest[rel.second], n);
      std::vector<std::vector<int>> partners(moved.size());
      for (const auto& [o, i] : corr.relations)
        if (4 * pair_count[{o, i}] >= strongest[i]) partners[i].push_back(o);
      auto inside = [&](const Element& e) {
        for (int v = 0; v < e.V.rows(); ++v)
          if (!region.contains(e.V.row(v).transpose())) return false;
        return true;
      };
      // Output elements take their deformed shape once they are merged with a partner.
      auto current = [&](int id) -> const Element& {
        auto it = deformed_out.find(id);
        return it == deformed_out.end() ? output[id] : it->second;
      };
      std::vector<char> busy(output.size(), 0);
      for (size_t i = 0; i < moved.size(); ++i) {
        const Element& in = moved[i];
        if (!in_domain(in)) continue;
        std::vector<int> related;
        for (const int o : partners[i])
          if (output.alive(o)) related.push_back(o);
        if (related.empty()) {
          // No partner: added as it is (if it fits among the existing elements).
          if (fits(in, {})) {
            output.add(in);
            ++stats.elements_added;
          } else {
            ++stats.rejected_intersecting;
          }
          continue;
        }
        if (inside(in)) {
          ++stats.elements_dropped;  // the output already has this element
          continue;
        }
        std::vector<int> replaced, crossing;
        for (const int o : related) (inside(output[o]) && !busy[o] ? replaced : crossing).push_back(o);
        if (crossing.empty()) {
          if (fits(in, replaced)) {
            for (const int o : replaced) output.remove(o);
            output.add(in);
            stats.elements_replaced += static_cast<int>(replaced.size());
          } else {
            ++stats.rejected_intersecting;
          }
          continue;
        }
        if (crossing.size() != 1 || busy[crossing[0]]) {
          ++stats.elements_dropped;
          continue;
        }
        const int o = crossing[0];
        const Element& base = current(o);
        // The same element placed twice (nearly identical, or mostly the same footprint, as for
        // two apples slightly apart): keep the output one rather than stitching two halves.
        if (elements_coincide(base, in, options.merging.coincidence_tolerance * mean_edge) ||
            footprint_overlap(base, in, mean_edge) >= options.merging.same_element_overlap) {
          ++stats.elements_matched;
          busy[o] = 1;
          continue;
        }
        StitchFailure why = StitchFailure::None;
        std::optional<Element> joined =
            cut_and_stitch(base, in, region, mean_edge, options.merging, &why);
        std::vector<int> ignore = replaced;
        ignore.push_back(o);
        if (joined && fits(*joined, ignore)) {
          for (const int r : replaced) output.remove(r);
          output.replace(o, std::move(*joined));
          busy.resize(output.size(), 0);
          busy[o] = 1;
          ++stats.elements_stitched;
        } else {
          ++stats.stitch_fallbacks;
          ++stats.stitch_failures[static_cast<int>(joined ? StitchFailure::None : why)];
        }
      }
      busy.resize(output.size(), 0);
    }
    mark_patch(patch_lo, patch_hi);
    grid.set_processed(seed);  // progress is guaranteed even if the patch is clipped
    report_progress(progress, "quilting", grid.num_processed(), grid.num_cells());
  }

  // Post-processing: elements outside the domain go; border elements stay whole unless trimmed.
  std::vector<const Element*> kept;
  std::vector<Element> trimmed;
  {
    ScopedStageTimer timer(times, "post-processing");
    trimmed.reserve(output.size());
    for (int id = 0; id < output.size(); ++id) {
      if (!output.alive(id)) continue;
      const Element& e = output[id];
      if (!in_domain(e)) {
        ++stats.removed_post;
        continue;
      }
      const bool crosses = e.lo.x() < domain_lo.x() || e.lo.y() < domain_lo.y() ||
                           e.hi.x() > domain_hi.x() || e.hi.y() > domain_hi.y();
      if (options.trim_border && crosses) {
        std::vector<int> faces;
        for (int f = 0; f < e.F.rows(); ++f) {
          const Vector3d c =
              (e.V.row(e.F(f, 0)) + e.V.row(e.F(f, 1)) + e.V.row(e.F(f, 2))).transpose() / 3.0;
          if (c.x() >= domain_lo.x() && c.y() >= domain_lo.y() && c.x() <= domain_hi.x() &&
              c.y() <= domain_hi.y())
            faces.push_back(f);
        }
        const TriMesh part = extract_faces(as_mesh(e), faces);
        Element t;
        t.V = part.V;
        t.F = part.F;
        t.update();
        trimmed.push_back(std::move(t));
        ++stats.trimmed;
        continue;
      }
      kept.push_back(&e);
    }
    for (const Element& e : trimmed) kept.push_back(&e);
  }
  TriMesh result = merge_elements(kept);
  // Back to the swatch's own axes (the thickness axis returns to where it was).
  const Eigen::Matrix3d back = swatch.rotation.transpose();
  result.V = (result.V * back.transpose()).eval();
  result.N = (result.N * back.transpose()).eval();
  report_progress(progress, "quilting", 1, 1);
  stats.faces = result.num_faces();
  stats.vertices = result.num_vertices();
  stats.elements = static_cast<int>(kept.size());
  if (stats_out) *stats_out = std::move(stats);
  return result;
}

}  // namespace mq
