#include "core/shell/shell_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"
#include "core/shell/shell_tetrahedra.h"

namespace mq {

namespace {

// SplitMix64 finaliser: decorrelates (seed, sweep, vertex) into one random 64-bit value.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

ShellMap::ShellMap(const MatrixX3d& V, const MatrixX3i& F, const ShellMapOptions& options) {
  MQ_CHECK(std::isfinite(options.height) && options.height > 0.0, InvalidInput,
           "shell map: height must be finite and > 0, got ", options.height);
  MQ_CHECK(V.allFinite(), InvalidInput, "shell map: vertices contain NaN or infinite values");
  MQ_CHECK(F.rows() > 0, InvalidInput, "shell map: the base has no faces");
  MQ_CHECK(options.repair_max_above >= 0 && options.repair_max_below >= 0 &&
               options.repair_max_shift >= 0 && options.exclusion_rings >= 0 &&
               options.max_exclusion_attempts >= 1 && options.max_excluded_share >= 0 &&
               options.max_excluded_share <= 1,
           InvalidInput,
           "shell map: repair bounds and exclusion rings must be >= 0, attempts >= 1 and the "
           "excluded share in [0, 1]");
  height_ = options.height;
  build_offset(V, F, options);
  number_shell_faces(F.rows());
  atlas_ = texture_atlas(base_V_, F_, options.atlas);
  build_problem(static_cast<int>(V.rows()));
  mark_fixed_corners(static_cast<int>(V.rows()));
  const Eigen::VectorXd vs = tet_volumes(problem_.shell_V, problem_.T);
  const Eigen::VectorXd vt = tet_volumes(problem_.texture_V, problem_.T);
  MQ_CHECK(vs.minCoeff() > 0.0, InternalError, "shell map: a shell tet is not positive");
  MQ_CHECK(vt.minCoeff() > 0.0, InternalError, "shell map: a texture tet is not positive");
}

// The offset surface over the base; where it fails, over a base whose folds are relaxed and
// then without the regions that still clash.
void ShellMap::build_offset(const MatrixX3d& V, const MatrixX3i& F,
                            const ShellMapOptions& options) {
  F_ = F;
  base_V_ = V;
  repair_.V = V;
  OffsetOptions oo = options.offset;
  oo.height = options.height;
  OffsetFailure failure;
  OffsetPairCache cache;  // each attempt of the fallback tests only what changed
  if (try_offset_surface(base_V_, F_, oo, offset_, failure, &cache)) return;
  if (!options.repair_folds && !options.exclude_regions) MQ_THROW(TopologyError, failure.reason);
  // Section 3.2 needs a valid shell; a folded base has none, so the shell is built over a
  // relaxed copy, which may slide a little along the base but not leave it (see
  // base_fold_repair.h). What the bounded repair leaves is judged by offset_surface itself.
  if (options.repair_folds && failure.fold) {
    FoldRepairOptions fo = options.fold_repair;
    fo.offset_criterion = true;
    fo.max_above = options.repair_max_above * height_;
    fo.max_below = options.repair_max_below * height_;
    fo.max_shift = options.repair_max_shift * height_;
    repair_ = repair_folds(V, F, fo);
    base_V_ = repair_.V;
  }
  exclude_until_valid(V, F, options, oo, failure, cache);
}

// Leaves out the faces where the offset surface fails, with rings of faces around them, and
// tries again, until it holds or the attempts or the excluded share run out (TopologyError).
void ShellMap::exclude_until_valid(const MatrixX3d& V, const MatrixX3i& F,
                                   const ShellMapOptions& options, const OffsetOptions& oo,
                                   OffsetFailure& failure, OffsetPairCache& cache) {
  const int n = static_cast<int>(V.rows());
  const Adjacency vf = vertex_faces(F, n);
  const Eigen::VectorXd area = face_areas(V, F);
  const double total = area.sum();
  std::vector<char> out(static_cast<size_t>(F.rows()), 0);
  std::vector<int> kept(static_cast<size_t>(F.rows()));  // shell face -> input face
  std::iota(kept.begin(), kept.end(), 0);
  // The first attempt is the failure above, unless the repair moved something.
  const bool retry = !repair_.moved_vertices.empty();
  for (int attempt = 0;; ++attempt) {
    if (attempt > 0 || retry) {
      F_.resize(static_cast<Eigen::Index>(kept.size()), 3);
      for (size_t i = 0; i < kept.size(); ++i)
        F_.row(static_cast<Eigen::Index>(i)) = F.row(kept[i]);
      if (try_offset_surface(base_V_, F_, oo, offset_, failure, &cache)) break;
    }
    MQ_CHECK(options.exclude_regions && attempt < options.max_exclusion_attempts, TopologyError,
             failure.reason);
    if (exclusion_.reason.empty()) exclusion_.reason = failure.reason;
    // The offending faces (of the shell's faces, numbered as F_) and exclusion_rings rings of
    // faces around them are left out; one ring more from half the attempts on, so that a clash
    // that moves on to the faces next to those left out ends in fewer attempts (each is a whole
    // offset_surface: the 108k-face dragon at scale 0.15 took 11 without it).
    std::vector<int> faces;
    for (const int f : failure.faces) faces.push_back(kept[static_cast<size_t>(f)]);
    const int rings =
        options.exclusion_rings + (2 * attempt >= options.max_exclusion_attempts ? 1 : 0);
    for (int ring = 0; ring < rings; ++ring) {
      std::vector<int> grown = faces;
      for (const int f : faces)
        for (int k = 0; k < 3; ++k) grown.insert(grown.end(), vf.begin(F(f, k)), vf.end(F(f, k)));
      faces.swap(grown);
    }
    for (const int f : faces) {
      if (!out[static_cast<size_t>(f)]) exclusion_.fold_faces += failure.fold;
      out[static_cast<size_t>(f)] = 1;
    }
    kept.clear();
    double left = 0;
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      if (out[static_cast<size_t>(f)])
        left += area(f);
      else
        kept.push_back(static_cast<int>(f));
    }
    exclusion_.area_share = total > 0 ? left / total : 1.0;
    MQ_CHECK(!kept.empty() && exclusion_.area_share <= options.max_excluded_share, TopologyError,
             exclusion_.reason, " (a valid shell would leave out ", 100 * exclusion_.area_share,
             "% of the base, over the ", 100 * options.max_excluded_share, "% allowed)");
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (out[static_cast<size_t>(f)]) exclusion_.faces.push_back(static_cast<int>(f));
}

// Each input face's shell face (-1: left out) and back.
void ShellMap::number_shell_faces(Eigen::Index num_faces) {
  shell_face_.assign(static_cast<size_t>(num_faces), -1);
  for (Eigen::Index f = 0, i = 0; f < num_faces; ++f) {
    if (std::binary_search(exclusion_.faces.begin(), exclusion_.faces.end(), static_cast<int>(f)))
      continue;
    shell_face_[static_cast<size_t>(f)] = static_cast<int>(i++);
    input_face_.push_back(static_cast<int>(f));
  }
}

// The stretch problem: three tets per shell face over the atlas's corners (base corner j, offset
// corner m + j), in the shell and in texture space (the chart's UV at heights 0 and h).
void ShellMap::build_problem(int n) {
  const int m = static_cast<int>(atlas_.UV.rows());
  const TetIndices T0 = shell_tet_indices(F_, n);
  problem_.T.resize(T0.rows(), 4);
  for (Eigen::Index t = 0; t < T0.rows(); ++t) {
    const Eigen::Index f = t / 3;
    for (int c = 0; c < 4; ++c) {
      const int x = T0(t, c);
      const int v = x % n;
      int k = 0;
      while (F_(f, k) != v) ++k;
      problem_.T(t, c) = atlas_.FUV(f, k) + (x >= n ? m : 0);
    }
  }
  problem_.shell_V.resize(2 * m, 3);
  problem_.texture_V.resize(2 * m, 3);
  for (int j = 0; j < m; ++j) {
    const int v = atlas_.uv_vertex[j];
    problem_.shell_V.row(j) = base_V_.row(v);
    problem_.shell_V.row(m + j) = offset_.V.row(v);
    problem_.texture_V.row(j) << atlas_.UV(j, 0), atlas_.UV(j, 1), 0.0;
    problem_.texture_V.row(m + j) << atlas_.UV(j, 0), atlas_.UV(j, 1), height_;
  }
}

// Fixed offset corners: on a chart border (the vertex has several UV rows) or the boundary.
void ShellMap::mark_fixed_corners(int n) {
  const int m = static_cast<int>(atlas_.UV.rows());
  std::vector<int> copies(n, 0);
  for (int j = 0; j < m; ++j) ++copies[atlas_.uv_vertex[j]];
  const EdgeTopology topo = edge_topology(F_, n);
  std::vector<char> on_boundary(n, 0);
  for (int e = 0; e < topo.num_edges(); ++e)
    if (topo.edge_faces.degree(e) != 2) on_boundary[topo.E(e, 0)] = on_boundary[topo.E(e, 1)] = 1;
  fixed_.assign(m, 0);
  for (int j = 0; j < m; ++j) {
    const int v = atlas_.uv_vertex[j];
    fixed_[j] = copies[v] > 1 || on_boundary[v];
  }
}

double ShellMap::stretch(TetStretchEvaluator& evaluator) const {
  return total_stretch(problem_, evaluator.per_tet(problem_));
}

double ShellMap::stretch() const {
  TetStretchCpu cpu;
  return stretch(cpu);
}

namespace {

// The tets of each offset corner j (vertex m + j): tets[offsets[j]] to tets[offsets[j + 1]].
struct CornerTets {
  std::vector<int> offsets, tets;
};

CornerTets corner_tets(const TetIndices& T, int m) {
  const int nt = static_cast<int>(T.rows());
  CornerTets ct;
  std::vector<int>& offsets = ct.offsets;
  offsets.assign(static_cast<size_t>(m) + 1, 0);
  for (int t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c)
      if (T(t, c) >= m) ++offsets[T(t, c) - m + 1];
  for (int j = 0; j < m; ++j) offsets[j + 1] += offsets[j];
  ct.tets.resize(offsets[m]);
  std::vector<int> fill(offsets.begin(), offsets.end() - 1);
  for (int t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c)
      if (T(t, c) >= m) ct.tets[fill[T(t, c) - m]++] = t;
  return ct;
}

// Greedy colouring of the free corners (not fixed, in some tet): two sharing a tet get different
// colours, so each colour's corners move in parallel. The corners by colour.
std::vector<std::vector<int>> colour_corners(const TetIndices& T, const CornerTets& ct,
                                             const std::vector<int>& free_vertices, int m) {
  std::vector<int> colour(m, -1);
  int num_colours = 0;
  std::vector<int> used_stamp;
  for (int j : free_vertices) {
    used_stamp.assign(num_colours + 1, 0);
    for (int a = ct.offsets[j]; a < ct.offsets[j + 1]; ++a)
      for (int c = 0; c < 4; ++c) {
        const int x = T(ct.tets[a], c) - m;
        if (x >= 0 && x != j && colour[x] >= 0) used_stamp[colour[x]] = 1;
      }
    int c = 0;
    while (used_stamp[c]) ++c;
    colour[j] = c;
    num_colours = std::max(num_colours, c + 1);
  }
  std::vector<std::vector<int>> by_colour(num_colours);
  for (int j : free_vertices) by_colour[colour[j]].push_back(j);
  return by_colour;
}

// One offset corner moved to lower the stretch of its tets: a line search along a random
// direction in the texture plane (seeded by sweep and corner), steps halving from the mean
// distance to its neighbours.
class CornerRelaxation {
 public:
  CornerRelaxation(const TetIndices& T, const MatrixX3d& S, MatrixX3d& X, const CornerTets& ct,
                   int m)
      : T_(T), S_(S), X_(X), ct_(ct), m_(m), shell_volume_(tet_volumes(S, T)) {}

  // The L2 stretch squared of corner j's tets, volume-weighted, with j at pos.
  double energy(int j, const Vector3d& pos) const {
    double e = 0.0;
    for (int a = ct_.offsets[j]; a < ct_.offsets[j + 1]; ++a) {
      const int t = ct_.tets[a];
      Vector3d s[4], x[4];
      for (int c = 0; c < 4; ++c) {
        s[c] = S_.row(T_(t, c));
        x[c] = T_(t, c) == m_ + j ? pos : Vector3d(X_.row(T_(t, c)));
      }
      const double l2 = tet_stretch(s, x);
      if (!std::isfinite(l2)) return kInf;
      e += l2 * l2 * shell_volume_(t);
    }
    return e;
  }

  // Whether corner j moved.
  bool relax(int j, int sweep, const ShellOptimizeOptions& options) {
    // One random angle per move: SplitMix64's output of (seed, sweep, corner) itself (seeding a
    // Mersenne twister per move, for one draw, was a fifth of the sweep's time).
    const std::uint64_t random =
        mix(mix(mix(options.seed ^ mix(static_cast<std::uint64_t>(sweep))) +
                static_cast<std::uint64_t>(j)));
    const double angle = kTwoPi * static_cast<double>(random >> 11) * (1.0 / 9007199254740992.0);
    const Vector3d dir(std::cos(angle), std::sin(angle), 0.0);
    const Vector3d p0 = X_.row(m_ + j);
    double len = 0.0;
    int count = 0;
    for (int a = ct_.offsets[j]; a < ct_.offsets[j + 1]; ++a)
      for (int c = 0; c < 4; ++c) {
        const int x = T_(ct_.tets[a], c);
        if (x >= m_ && x != m_ + j) {
          len += (Vector3d(X_.row(x)) - p0).norm();
          ++count;
        }
      }
    if (count == 0) return false;
    len /= count;
    const double e0 = energy(j, p0);
    double best = e0;
    Vector3d best_p = p0;
    double step = len;
    for (int k = 0; k < options.line_search_steps; ++k, step *= 0.5) {
      for (const double sign : {1.0, -1.0}) {
        const Vector3d p = p0 + sign * step * dir;
        const double e = energy(j, p);
        if (e < best) {
          best = e;
          best_p = p;
        }
      }
    }
    if (!(best < e0)) return false;
    X_.row(m_ + j) = best_p;
    return true;
  }

 private:
  const TetIndices& T_;
  const MatrixX3d& S_;
  MatrixX3d& X_;
  const CornerTets& ct_;
  const int m_;
  const Eigen::VectorXd shell_volume_;
};

}  // namespace

ShellOptimizeReport ShellMap::optimize(TetStretchEvaluator& evaluator,
                                       const ShellOptimizeOptions& options) {
  MQ_CHECK(options.max_sweeps >= 0, InvalidInput, "shell optimize: max_sweeps must be >= 0");
  MQ_CHECK(options.tolerance >= 0.0, InvalidInput, "shell optimize: tolerance must be >= 0");
  MQ_CHECK(options.line_search_steps >= 1, InvalidInput,
           "shell optimize: line_search_steps must be >= 1");
  const int m = static_cast<int>(atlas_.UV.rows());
  const CornerTets ct = corner_tets(problem_.T, m);
  std::vector<int> free_vertices;
  for (int j = 0; j < m; ++j)
    if (!fixed_[j] && ct.offsets[j + 1] > ct.offsets[j]) free_vertices.push_back(j);
  const std::vector<std::vector<int>> by_colour = colour_corners(problem_.T, ct, free_vertices, m);
  CornerRelaxation relaxation(problem_.T, problem_.shell_V, problem_.texture_V, ct, m);

  ShellOptimizeReport report;
  report.num_colours = static_cast<int>(by_colour.size());
  report.num_free_vertices = static_cast<int>(free_vertices.size());
  report.stretch_before = stretch(evaluator);
  double current = report.stretch_before;
  std::vector<char> accepted(m, 0);
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    for (const std::vector<int>& group : by_colour) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, group.size()),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                            accepted[group[i]] = relaxation.relax(group[i], sweep, options);
                        });
    }
    for (int j : free_vertices) report.accepted_moves += accepted[j];
    const double next = stretch(evaluator);
    ++report.sweeps;
    MQ_ASSERT(next <= current * (1 + 1e-9));  // every accepted move lowers its local sum
    const double improvement = (current - next) / current;
    current = next;
    if (improvement < options.tolerance) break;
  }
  report.stretch_after = current;
  return report;
}

}  // namespace mq
