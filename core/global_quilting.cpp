#include "core/global_quilting.h"

#include <tbb/parallel_for.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/element_kinds.h"
#include "core/errors.h"
#include "core/geometry_measures.h"
#include "core/global_parameterization.h"
#include "core/line_field.h"
#include "core/mesh_topology.h"
#include "core/planar_quilting.h"
#include "core/quilt_elements.h"
#include "core/swatch_symmetry.h"
#include "core/tangent_field.h"
#include "core/weld_vertices.h"

namespace mq {

namespace {

// The parameter-plane triangles binned in a uniform grid, for "which faces contain point p".
class ChartGrid {
 public:
  ChartGrid(const GlobalParameterization& gp, int num_faces) : gp_(gp) {
    lo_ = gp.wedge_uv.colwise().minCoeff().transpose();
    const Vector2d hi = gp.wedge_uv.colwise().maxCoeff().transpose();
    const double side = std::max((hi - lo_).maxCoeff(), 1e-12);
    const int n = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(num_faces))));
    cell_ = side / n;
    nx_ = std::max(1, static_cast<int>((hi.x() - lo_.x()) / cell_) + 1);
    ny_ = std::max(1, static_cast<int>((hi.y() - lo_.y()) / cell_) + 1);
    cells_.assign(static_cast<size_t>(nx_) * ny_, {});
    for (int f = 0; f < num_faces; ++f) {
      Vector2d a = gp.uv(f, 0), b = a;
      for (int k = 1; k < 3; ++k) {
        a = a.cwiseMin(gp.uv(f, k));
        b = b.cwiseMax(gp.uv(f, k));
      }
      for (int y = cy(a.y()); y <= cy(b.y()); ++y)
        for (int x = cx(a.x()); x <= cx(b.x()); ++x)
          cells_[static_cast<size_t>(y) * nx_ + x].push_back(f);
    }
  }
  // Faces whose triangle contains p (closed), ascending.
  std::vector<int> containing(const Vector2d& p) const {
    std::vector<int> out;
    for (const int f : cells_[static_cast<size_t>(cy(p.y())) * nx_ + cx(p.x())]) {
      const Vector2d a = gp_.uv(f, 0), b = gp_.uv(f, 1), c = gp_.uv(f, 2);
      const Vector2d e0 = b - a, e1 = c - a, d = p - a;
      const double den = e0.x() * e1.y() - e1.x() * e0.y();
      if (!(std::abs(den) > 0)) continue;
      const double v = (d.x() * e1.y() - e1.x() * d.y()) / den;
      const double w = (e0.x() * d.y() - d.x() * e0.y()) / den;
      if (v >= 0 && w >= 0 && v + w <= 1) out.push_back(f);
    }
    return out;
  }

 private:
  int cx(double x) const { return std::clamp(static_cast<int>((x - lo_.x()) / cell_), 0, nx_ - 1); }
  int cy(double y) const { return std::clamp(static_cast<int>((y - lo_.y()) / cell_), 0, ny_ - 1); }
  const GlobalParameterization& gp_;
  Vector2d lo_;
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
};

bool share_wedge(const GlobalParameterization& gp, int f, int g) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (gp.corner_wedge(f, i) == gp.corner_wedge(g, j)) return true;
  return false;
}

}  // namespace

namespace {

// One implicit step of the uniform Laplacian, x' = (I + w L)^-1 x, then scaled back to the
// base's area about the centroid (the step shrinks): detail of about an edge's size is gone.
MatrixX3d smoothed_positions(const TriMesh& base, const EdgeTopology& topo, double weight) {
  const int nv = base.num_vertices();
  std::vector<Eigen::Triplet<double>> t;
  std::vector<double> degree(static_cast<size_t>(nv), 0);
  for (int e = 0; e < topo.num_edges(); ++e) {
    const int a = topo.E(e, 0), b = topo.E(e, 1);
    t.emplace_back(a, b, -weight);
    t.emplace_back(b, a, -weight);
    degree[a] += weight;
    degree[b] += weight;
  }
  for (int v = 0; v < nv; ++v) t.emplace_back(v, v, 1.0 + degree[v]);
  Eigen::SparseMatrix<double> M(nv, nv);
  M.setFromTriplets(t.begin(), t.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
  MQ_CHECK(ldlt.info() == Eigen::Success, SolverFailure,
           "global parameterisation: the smoothing system could not be factorised");
  const Eigen::MatrixXd X = base.V;
  MatrixX3d S = ldlt.solve(X);
  const double a0 = surface_area(base.V, base.F), a1 = surface_area(S, base.F);
  if (!(a1 > 0) || !S.allFinite()) return base.V;
  const double k = std::sqrt(a0 / a1);
  const Vector3d c0 = S.colwise().mean().transpose(), c1 = base.V.colwise().mean().transpose();
  for (Eigen::Index v = 0; v < S.rows(); ++v)
    S.row(v) = (c1 + k * (S.row(v).transpose() - c0)).transpose();
  return S;
}

// Median over faces (by area) of the linear scale sqrt(area in the plane / area on the base).
double median_scale(const GlobalParameterization& gp, const TriMesh& base) {
  std::vector<std::pair<double, double>> s;  // (scale, area)
  double total = 0;
  for (int f = 0; f < base.num_faces(); ++f) {
    const Vector2d a = gp.uv(f, 0), b = gp.uv(f, 1), c = gp.uv(f, 2);
    const double ap = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    const Vector3d p0 = base.V.row(base.F(f, 0)), p1 = base.V.row(base.F(f, 1)),
                   p2 = base.V.row(base.F(f, 2));
    const double a3 = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    if (!(a3 > 0)) continue;
    s.emplace_back(std::sqrt(ap / a3), a3);
    total += a3;
  }
  if (s.empty()) return 1;
  std::sort(s.begin(), s.end());
  double acc = 0;
  for (const auto& [scale, area] : s) {
    acc += area;
    if (acc >= 0.5 * total) return scale > 0 ? scale : 1;
  }
  return 1;
}

// Nearest point of offset + lattice(a, b) to x.
Vector2d nearest_symmetry(const SwatchSymmetry& sym, const Vector2d& x, const Vector2d& offset) {
  Eigen::Matrix2d basis;
  basis.col(0) = sym.a;
  basis.col(1) = sym.b;
  const Vector2d k = basis.inverse() * (x - offset);
  return offset + basis * Vector2d(std::round(k.x()), std::round(k.y()));
}

// The parameterisation, made seamless for a texture with the given symmetries: solved once,
// scaled so that its median scale is 1 (texture at its nominal size on most of the base); then
// the half-turn cones pinned to the texture's half-turn centres ((c + lattice) / 2 in the plane
// quilt's coordinates, which start at `anchor`), which makes every transition around them a
// symmetry of the texture; then the translation of every cut path (a handle, a path between
// boundaries, or one still off after the pins) fixed at the nearest symmetry. Each stage is one
// more solve of the same size.
GlobalParameterization seamless_parameterization(const MatrixX3d& V, const TriMesh& base,
                                                 const SurfaceJob& job, const DirectionField& df,
                                                 const SwatchSymmetry& sym, bool seamless,
                                                 Vector2d& anchor, GlobalQuiltingStats& stats) {
  GlobalParameterizationOptions go;
  GlobalParameterization gp = global_parameterization(V, base.F, job.topo, job.TT, df, go);
  const double sigma = median_scale(gp, base);
  gp.wedge_uv /= sigma;
  go.target_scale = 1.0 / sigma;
  stats.scale_correction = 1.0 / sigma;
  anchor = gp.wedge_uv.colwise().minCoeff().transpose();
  if (!seamless || !sym.periodic || !sym.half_turn) return gp;
  // On a closed component the transitions around all its cones compose to the identity, so
  // the cones' places are not independent: each pinned to its nearest half-turn centre, the
  // product of their half turns is in general a lattice translation, not the identity, and the
  // soft pins then share that period out between them (knight: every pin 0.026 periods off,
  // transitions up to 1.1 periods off a symmetry). Pinned all but one, the last is
  // where the others put it: a half-turn centre too, since a product of half turns about
  // half-turn centres is a symmetry. The one left free is the cone its pin would move most.
  std::vector<int> face_component;
  const int components = connected_components(base.F, base.num_vertices(), face_component);
  std::vector<char> closed(static_cast<size_t>(components), 1);
  for (int e = 0; e < job.topo.num_edges(); ++e)
    if (job.topo.edge_faces.degree(e) != 2 && job.topo.edge_faces.degree(e) > 0)
      closed[face_component[job.topo.edge_faces.begin(e)[0]]] = 0;
  std::vector<int> free_pin(static_cast<size_t>(components), -1);
  std::vector<double> free_shift(static_cast<size_t>(components), -1);
  std::vector<char> pinned(static_cast<size_t>(base.num_vertices()), 0);
  for (int f = 0; f < base.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = base.F(f, k);
      if (pinned[v] || df.index[v] % 2 == 0) continue;
      pinned[v] = 1;
      const Vector2d x = gp.uv(f, k) - anchor;
      const Vector2d at = anchor + 0.5 * nearest_symmetry(sym, 2 * x, sym.c);
      const int c = face_component[static_cast<size_t>(f)];
      const double shift = (at - gp.uv(f, k)).norm();
      if (closed[c] && shift > free_shift[c]) {
        free_shift[c] = shift;
        free_pin[c] = static_cast<int>(go.pinned.size());
      }
      go.pinned.emplace_back(v, at);
    }
  {
    std::vector<char> keep(go.pinned.size(), 1);
    for (const int i : free_pin)
      if (i >= 0) keep[static_cast<size_t>(i)] = 0;
    std::vector<std::pair<int, Vector2d>> kept;
    for (size_t i = 0; i < go.pinned.size(); ++i)
      if (keep[i]) kept.push_back(go.pinned[i]);
    go.pinned = std::move(kept);
  }
  stats.pinned_cones = static_cast<int>(go.pinned.size());
  gp = global_parameterization(V, base.F, job.topo, job.TT, df, go);
  // In plane coordinates a transition uv_g = s uv_f + t has translation t + (s - 1) anchor.
  auto target = [&](const CutPath& path, const Vector2d& t) {
    const Vector2d tp = t + (path.sign - 1) * anchor;
    return nearest_symmetry(sym, tp, path.sign > 0 ? Vector2d::Zero() : sym.c);
  };
  for (const CutPath& path : cut_paths(gp, job.topo, base.F)) {
    const Vector2d rounded =
        target(path, path_translation(gp, job.topo, base.F, path)) - (path.sign - 1) * anchor;
    for (size_t k = 0; k < path.edges.size(); ++k)
      go.fixed_translation.emplace_back(path.edges[k], edge_translation(path, k, rounded));
  }
  gp = global_parameterization(V, base.F, job.topo, job.TT, df, go);
  stats.seamless = true;
  // How far the transitions stayed from the texture's symmetries (the constraints are soft).
  const double period = std::min(sym.a.norm(), sym.b.norm());
  for (const CutPath& path : cut_paths(gp, job.topo, base.F)) {
    ++stats.cut_paths;
    const Vector2d t = path_translation(gp, job.topo, base.F, path) + (path.sign - 1) * anchor;
    stats.worst_transition_error =
        std::max(stats.worst_transition_error,
                 (t - target(path, t - (path.sign - 1) * anchor)).norm() / period);
  }
  return gp;
}

}  // namespace

namespace {

// The global method from a prepared job and the swatch's symmetry (found on job.swatch).
SurfaceQuilt quilt_prepared_global(SurfaceJob& job, const PreparedSwatch& swatch,
                                   const SwatchSymmetry& symmetry,
                                   const SurfaceQuiltingOptions& options,
                                   TranslationCostEvaluator& evaluator, SurfaceQuiltingStats stats,
                                   SurfaceQuiltingStats* stats_out, GlobalQuiltingStats* global_out,
                                   ProgressSink* progress) {
  GlobalQuiltingStats gstats;
  StageTimes& times = stats.times;
  const TriMesh& base = job.base;
  stats.shell_height = swatch.size.z();
  gstats.periodic = symmetry.periodic;

  // The line field and the parameterisation, on a smoothed copy of the base (same
  // connectivity): detail of an edge's size would otherwise put a cone at every sharp corner of
  // a coarse model. Measured, interior rings with the swatch's 4 links, without / with one step:
  // Spot 93.8 / 95.5%, knight 82.3 / 87.3%, bunny 95.7 / 96.8%, cup 97.9 / 98.6%.
  GlobalParameterization gp;
  Vector2d anchor = Vector2d::Zero();
  {
    ScopedStageTimer timer(times, "parameterization");
    ScopedStageProgress shown(progress, "parameterization");
    const MatrixX3d V = options.global.smoothing > 0
                            ? smoothed_positions(base, job.topo, options.global.smoothing)
                            : base.V;
    // The guidance (the user's field, or the smooth default along the longest box axis) is
    // followed weakly; when that leaves a pole (an index-1 singularity: no cut can end there,
    // the charts would fold around it), the smoothest line field, turned towards the guidance.
    // Always the smoothest field measured worse on the shipped bases (interior rings with 4
    // links, weighted / smoothest: knight 87.9 / 72.1%, bunny 96.5 / 94.3%, Spot 95.3 / 94.0%,
    // cup 98.4 / 97.8%); the weighted fit left poles on a smoothed icosphere.
    LineFieldOptions lo;
    lo.N = 2;
    lo.guidance_weight = options.global.guidance_weight;
    DirectionField df = smooth_direction_field(V, base.F, job.topo, job.TT, job.field, lo);
    const auto has_pole = [](const DirectionField& f) {
      for (const int i : f.index)
        if (i != 0 && i % f.N == 0) return true;
      return false;
    };
    if (!lo.smoothest && has_pole(df)) {
      lo.smoothest = true;
      df = smooth_direction_field(V, base.F, job.topo, job.TT, job.field, lo);
    }
    // A + and a - cone side by side (the tip and the foot of a spike one ring across) serve no
    // ring and each wrecks the rings around it (knight: 8 such pairs of 42 cones; rings off the
    // surface 63 -> 17; with ring separation, interior rings with 4 links 89.5 -> 91.3%).
    if (options.global.cancel_cone_pairs)
      gstats.cancelled_cone_pairs = cancel_singular_pairs(V, base.F, job.topo, df);
    gp = seamless_parameterization(V, base, job, df, symmetry, options.global.seamless, anchor,
                                   gstats);
  }
  gstats.singular_vertices = gp.num_singular;
  gstats.cut_edges = gp.num_cut_edges;

  // The plane texture over the parameter plane's box. Seamless, the plane's origin stays at the
  // anchor, moved back by a lattice vector if the parameterisation reaches beyond it.
  Vector2d lo = gp.wedge_uv.colwise().minCoeff().transpose();
  const Vector2d hi = gp.wedge_uv.colwise().maxCoeff().transpose();
  if (gstats.seamless) {
    const Vector2d need = (anchor - lo).cwiseMax(0.0);
    Vector2d shift = Vector2d::Zero();
    if (need.squaredNorm() > 0)
      shift = nearest_symmetry(symmetry,
                               need + Vector2d::Constant(symmetry.a.norm() + symmetry.b.norm()),
                               Vector2d::Zero());
    lo = anchor - shift;
  }
  PlanarQuiltingOptions po;
  po.length = std::max(hi.x() - lo.x(), swatch.size.x());
  po.width = std::max(hi.y() - lo.y(), swatch.size.y());
  po.matching = options.matching;
  po.matching.refine_to = PlanarQuiltingOptions().matching.refine_to;
  po.correspondence = options.patch.correspondence;
  po.merging = options.patch.merging;
  po.deform = options.patch.deform;
  po.seed = options.seed;
  gstats.parameter_area = po.length * po.width;
  TriMesh plane;
  if (options.global.tile && tileable(swatch, symmetry)) {
    ScopedStageTimer timer(times, "tiling");
    ScopedStageProgress shown(progress, "tiling");
    plane = tile_lattice(swatch, symmetry, Vector2d::Zero(), Vector2d(po.length, po.width),
                         &gstats.orbits);
    gstats.tiled = true;
    stats.iterations = 1;
    stats.cell_size = matching_cell_size(swatch);
  } else {
    PlanarQuiltingStats ps;
    plane = quilt_plane(job.swatch, po, evaluator, &ps, progress);
    stats.iterations = ps.iterations;
    stats.cell_size = ps.cell_size;
    stats.matched_point_offsets = ps.matched_point_offsets;
    stats.counts = ps.counts;
    for (const auto& [stage, seconds] : ps.times.stages()) times.add(stage, seconds);
    // Back into the synthesis frame (thickness along z).
    plane.V = (plane.V * swatch.rotation.transpose()).eval();
  }
  plane.V.col(0).array() += lo.x();
  plane.V.col(1).array() += lo.y();

  // Every element onto the base, from each face whose chart contains its centre.
  std::vector<SurfaceElement> placed;
  {
    ScopedStageTimer timer(times, "placement");
    ScopedStageProgress shown(progress, "placement");
    const ChartGrid grid(gp, base.num_faces());
    std::vector<int> fc;
    const int n = connected_components(plane.F, plane.num_vertices(), fc);
    const std::vector<std::vector<int>> groups = component_faces(fc, n);
    std::vector<std::vector<SurfaceElement>> per(static_cast<size_t>(n));
    std::vector<int> off(static_cast<size_t>(n), 0);
    // In blocks, so that progress is reported from this thread between them (each element's
    // placement depends only on it: the result is the same whatever the blocks).
    const int block = std::max(64, n / 50);
    for (int first = 0; first < n; first += block) {
      report_progress(progress, "placement", first, n);
      tbb::parallel_for(first, std::min(n, first + block), [&](int c) {
        const TriMesh part = extract_faces(plane, groups[c]);
        const Vector2d centre = part.V.leftCols<2>().colwise().mean().transpose();
        // One placement per place on the surface: faces of one chart around the centre (it lies
        // on their common edge or vertex) are the same place.
        std::vector<int> starts;
        for (const int f : grid.containing(centre)) {
          bool same = false;
          for (const int g : starts) same = same || share_wedge(gp, f, g);
          if (!same) starts.push_back(f);
        }
        for (const int f0 : starts) {
          SurfaceElement s;
          s.F = part.F;
          s.kind = has_kinds(plane) ? plane.face_kind[static_cast<size_t>(groups[c][0])] : 0;
          s.face.resize(part.V.rows());
          s.barycentric.resize(part.V.rows(), 3);
          s.height.resize(part.V.rows());
          int face = f0;
          ChartTransform to_current;  // from f0's chart to the walk's current face's
          bool ok = true;
          for (Eigen::Index v = 0; v < part.V.rows() && ok; ++v) {
            Vector2d x = to_current(part.V.row(v).head<2>().transpose());
            Vector3d b;
            ok = locate_in_charts(gp, job.topo, job.TT, base.F, face, x, b, 256, &to_current);
            s.face[v] = face;
            s.barycentric.row(v) = b.transpose();
            s.height(v) = std::clamp(part.V(v, 2), 0.0, swatch.size.z());
          }
          if (ok) {
            s.flat = part.V;
            per[c].push_back(std::move(s));
          } else
            ++off[c];
        }
      });
    }
    for (int c = 0; c < n; ++c) {
      gstats.off_surface += off[c];
      for (SurfaceElement& s : per[c]) placed.push_back(std::move(s));
    }
  }
  gstats.placed = static_cast<int>(placed.size());

  SurfaceQuilt quilt;
  quilt.kinds = swatch.kinds;
  quilt.shell_height = swatch.size.z();
  quilt.base = job.base;
  quilt.input_base = std::move(job.cleaned);
  quilt.refinement = std::move(job.refinement);
  quilt.elements = std::move(placed);
  stats.elements = static_cast<int>(quilt.elements.size());
  for (const SurfaceElement& e : quilt.elements) {
    stats.faces += static_cast<int>(e.F.rows());
    stats.vertices += static_cast<int>(e.face.size());
  }
  report_progress(progress, "quilting", 1, 1);
  if (stats_out) *stats_out = std::move(stats);
  if (global_out) *global_out = gstats;
  return quilt;
}

SwatchSymmetry timed_symmetry(const PreparedSwatch& swatch, StageTimes& times) {
  ScopedStageTimer timer(times, "symmetry");
  const SwatchFaceTree tree(swatch.mesh.V, swatch.mesh.F);
  return detect_swatch_symmetry(swatch, tree, matching_cell_size(swatch));
}

}  // namespace

SurfaceQuilt quilt_surface_global(const TriMesh& base_in, const TriMesh& swatch_mesh,
                                  const SurfaceQuiltingOptions& options,
                                  TranslationCostEvaluator& evaluator,
                                  SurfaceQuiltingStats* stats_out, GlobalQuiltingStats* global_out,
                                  ProgressSink* progress) {
  SurfaceQuiltingStats stats;
  SurfaceJob job = prepare_surface_job(base_in, swatch_mesh, options, stats);
  const PreparedSwatch swatch = prepare_swatch(job.swatch);
  const SwatchSymmetry symmetry = timed_symmetry(swatch, stats.times);
  return quilt_prepared_global(job, swatch, symmetry, options, evaluator, std::move(stats),
                               stats_out, global_out, progress);
}

SurfaceQuilt quilt_surface_auto(const TriMesh& base_in, const TriMesh& swatch_mesh,
                                const SurfaceQuiltingOptions& options,
                                TranslationCostEvaluator& evaluator,
                                SurfaceQuiltingStats* stats_out, GlobalQuiltingStats* global_out,
                                ProgressSink* progress, bool* used_global) {
  SurfaceQuiltingStats stats;
  SurfaceJob job = prepare_surface_job(base_in, swatch_mesh, options, stats);
  const PreparedSwatch swatch = prepare_swatch(job.swatch);
  bool repeating = false;
  {
    ScopedStageTimer timer(stats.times, "method choice");
    repeating = repeating_elements(swatch);
  }
  if (repeating) {
    // The symmetry decides and, for a lattice, is the one the layout uses: found once.
    const SwatchSymmetry symmetry = timed_symmetry(swatch, stats.times);
    if (tileable(swatch, symmetry)) {
      if (used_global) *used_global = true;
      return quilt_prepared_global(job, swatch, symmetry, options, evaluator, std::move(stats),
                                   stats_out, global_out, progress);
    }
  }
  if (used_global) *used_global = false;
  // The job prepared once (a large base is simplified in the preparation).
  return quilt_prepared_surface(std::move(job), std::move(stats), options, evaluator, stats_out,
                                progress);
}

}  // namespace mq
