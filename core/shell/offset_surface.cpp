#include "core/shell/offset_surface.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/shell/shell_tetrahedra.h"

namespace mq {

namespace {

// A direction must keep at least this cosine with every incident face normal.
constexpr double kMinCosine = 0.1;
// Shell tets flatter than this (volume / longest edge^3) count as invalid while offsetting:
// far above the 1e-12 of shell_tetrahedra, so the result always passes there.
constexpr double kMinRelativeVolume = 1e-6;

double min_face_cosine(const Vector3d& d, const MatrixX3d& FN, const Adjacency& vf, int i) {
  double c = 1.0;
  for (const int* f = vf.begin(i); f != vf.end(i); ++f) c = std::min(c, d.dot(FN.row(*f)));
  return c;
}

// The unit direction maximising the smallest cosine with the incident face normals (a
// spherical minimax centre): the optimum has one, two or three active normals, so it is the
// best of the normals, the normalised pair sums and the directions equidistant from triples.
// Used where the area-weighted normal is below kMinCosine to some face (sharp vertices): a
// prism whose corner direction lies below a face's plane is inverted at every height.
Vector3d cone_direction(const Vector3d& normal, const MatrixX3d& FN, const Adjacency& vf, int i) {
  Vector3d best = normal;
  double best_cos = min_face_cosine(normal, FN, vf, i);
  auto consider = [&](Vector3d d) {
    const double len = d.norm();
    if (!(len > 1e-12)) return;
    d /= len;
    const double c = min_face_cosine(d, FN, vf, i);
    if (c > best_cos) {
      best_cos = c;
      best = d;
    }
  };
  const int* f = vf.begin(i);
  const int k = vf.degree(i);
  for (int a = 0; a < k; ++a) {
    const Vector3d na = FN.row(f[a]);
    consider(na);
    for (int b = a + 1; b < k; ++b) {
      const Vector3d nb = FN.row(f[b]);
      consider(na + nb);
      for (int c = b + 1; c < k; ++c) {
        const Vector3d d = (na - nb).cross(na - Vector3d(FN.row(f[c])));
        consider(d);
        consider(-d);
      }
    }
  }
  return best;
}

// Laplacian diffusion of the normals, refusing steps that leave a vertex's face cone. Vertices
// with no normal, or with no direction above all their faces (the base folds there), are
// listed in `bad` (ascending) and the directions are then not diffused; `message` names the
// first.
MatrixX3d smoothed_directions(const MatrixX3d& V, const MatrixX3i& F, int iterations,
                              std::vector<int>& bad, std::string& message) {
  const int n = static_cast<int>(V.rows());
  const MatrixX3d FN = face_normals(V, F);
  const Adjacency vv = vertex_adjacency(F, n);
  const Adjacency vf = vertex_faces(F, n);
  MatrixX3d D = vertex_normals(V, F);
  for (int i = 0; i < n; ++i) {
    if (vf.degree(i) > 0 && !(D.row(i).squaredNorm() > 0.5)) {
      if (bad.empty())
        message = detail::concat("offset surface: vertex ", i, " has no normal (its faces cancel)");
      bad.push_back(i);
      continue;
    }
    if (vf.degree(i) == 0 || min_face_cosine(D.row(i), FN, vf, i) >= kMinCosine) continue;
    D.row(i) = cone_direction(D.row(i), FN, vf, i);
    if (!(min_face_cosine(D.row(i), FN, vf, i) > 0.0)) {
      if (bad.empty())
        message = detail::concat(
            "offset surface: vertex ", i, " (", V(i, 0), " ", V(i, 1), " ", V(i, 2),
            ") has no direction above all its faces (the base folds there), so no valid "
            "shell prism exists at any height");
      bad.push_back(i);
    }
  }
  if (!bad.empty()) return D;
  for (int it = 0; it < iterations; ++it) {
    MatrixX3d next = D;
    tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
      for (int i = r.begin(); i != r.end(); ++i) {
        if (vf.degree(i) == 0) continue;
        Vector3d s = D.row(i);
        for (const int* j = vv.begin(i); j != vv.end(i); ++j) s += D.row(*j).transpose();
        const double len = s.norm();
        if (!(len > 1e-12)) continue;
        s /= len;
        const Vector3d cur = D.row(i);
        const double bound = std::min(kMinCosine, min_face_cosine(cur, FN, vf, i));
        if (min_face_cosine(s, FN, vf, i) >= bound) next.row(i) = s;
      }
    });
    D.swap(next);
  }
  return D;
}

// The diffusion steps offset_directions takes.
int diffusion_steps(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options) {
  options.validate_smoothing();
  int steps = options.smoothing_iterations;
  const double mean_edge = mean_edge_length(V, F);
  if (mean_edge > 0 && std::isfinite(options.height)) {
    const double reach = options.smoothing_radius * options.height / mean_edge;
    // Bounded: past 10^4 steps the reach is far beyond any shell (the base is degenerate).
    steps = std::max(steps, static_cast<int>(std::ceil(std::min(reach * reach, 1e4))));
  }
  return steps;
}

// Whether shell tet t is flat or inverted: its volume at most kMinRelativeVolume times its
// longest edge cubed.
bool flat_tet(const MatrixX3d& S, const TetIndices& T, Eigen::Index t) {
  const Vector3d p[4] = {S.row(T(t, 0)), S.row(T(t, 1)), S.row(T(t, 2)), S.row(T(t, 3))};
  double l2 = 0.0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) l2 = std::max(l2, (p[a] - p[b]).squaredNorm());
  return !(tet_volume(p[0], p[1], p[2], p[3]) > kMinRelativeVolume * l2 * std::sqrt(l2));
}

// kept (pairs of faces that did not move, sorted) and the pairs with a moved face, merged in
// order: what a full test of the shell S with boundary faces B finds.
std::vector<std::pair<int, int>> with_moved_pairs(const std::vector<std::pair<int, int>>& kept,
                                                  const MatrixX3d& S, const MatrixX3i& B,
                                                  const std::vector<char>& moved) {
  const std::vector<std::pair<int, int>> fresh = intersecting_face_pairs_touching(S, B, moved);
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(kept.size() + fresh.size());
  std::merge(kept.begin(), kept.end(), fresh.begin(), fresh.end(), std::back_inserter(pairs));
  return pairs;
}

// The pairs of the shell S with boundary faces B that a full test would find, given an earlier
// shell's (cache: the same vertex count): the earlier pairs of two faces that are in both
// shells with bitwise the same corners, renumbered, and a test of the faces that are new or
// moved against all.
std::vector<std::pair<int, int>> pairs_after(const MatrixX3d& S, const MatrixX3i& B,
                                             const OffsetPairCache& cache) {
  const auto key = [](const MatrixX3i& M, Eigen::Index f) {
    return std::array<int, 3>{M(f, 0), M(f, 1), M(f, 2)};
  };
  std::vector<std::pair<std::array<int, 3>, int>> old_rows(static_cast<size_t>(cache.B.rows()));
  for (Eigen::Index f = 0; f < cache.B.rows(); ++f)
    old_rows[static_cast<size_t>(f)] = {key(cache.B, f), static_cast<int>(f)};
  std::sort(old_rows.begin(), old_rows.end());
  std::vector<char> same_vertex(static_cast<size_t>(S.rows()));
  for (Eigen::Index v = 0; v < S.rows(); ++v)
    same_vertex[static_cast<size_t>(v)] = S.row(v) == cache.S.row(v) ? 1 : 0;
  std::vector<char> moved(static_cast<size_t>(B.rows()), 1);
  std::vector<int> new_row(static_cast<size_t>(cache.B.rows()), -1);
  for (Eigen::Index f = 0; f < B.rows(); ++f) {
    const std::array<int, 3> k = key(B, f);
    const auto it = std::lower_bound(old_rows.begin(), old_rows.end(), std::make_pair(k, -1));
    if (it == old_rows.end() || it->first != k) continue;
    if (!same_vertex[static_cast<size_t>(k[0])] || !same_vertex[static_cast<size_t>(k[1])] ||
        !same_vertex[static_cast<size_t>(k[2])])
      continue;
    moved[static_cast<size_t>(f)] = 0;
    new_row[static_cast<size_t>(it->second)] = static_cast<int>(f);
  }
  std::vector<std::pair<int, int>> kept;
  for (const auto& [a, b] : cache.pairs) {
    const int f = new_row[static_cast<size_t>(a)], g = new_row[static_cast<size_t>(b)];
    if (f >= 0 && g >= 0) kept.emplace_back(std::min(f, g), std::max(f, g));
  }
  std::sort(kept.begin(), kept.end());
  return with_moved_pairs(kept, S, B, moved);
}

// Intersecting pairs of shell boundary faces, kept from round to round. A round re-tests only
// the pairs with a face that moved (an offset vertex lowered): the others keep last round's
// answer, so every round sees exactly the pairs a full test would, at the cost of the faces
// that moved (on a 1.1M-face base the full test every round was most of the shell's cost).
// The first round starts from an earlier call's (cache) when there is one.
class ShellPairs {
 public:
  explicit ShellPairs(OffsetPairCache* cache) : cache_(cache) {}

  // The pairs of the shell S (base then offset vertices, n each) with offset heights `heights`.
  const std::vector<std::pair<int, int>>& update(const MatrixX3d& S, const MatrixX3i& B, int n,
                                                 const Eigen::VectorXd& heights) {
    if (first_) {
      if (cache_ && cache_->S.rows() == S.rows()) {
        pairs_ = pairs_after(S, B, *cache_);
      } else {
        IntersectionOptions all_pairs;
        all_pairs.between_components_only = false;
        pairs_ = intersecting_face_pairs(S, B, all_pairs);
      }
      if (cache_) *cache_ = OffsetPairCache{S, B, pairs_};
      first_ = false;
    } else {
      std::vector<char> moved(static_cast<size_t>(B.rows()), 0);
      for (Eigen::Index f = 0; f < B.rows(); ++f)
        for (int k = 0; k < 3; ++k) {
          const int v = B(f, k);
          if (v >= n && heights(v - n) != tested_heights_(v - n)) moved[f] = 1;
        }
      std::vector<std::pair<int, int>> kept;
      for (const auto& [f, g] : pairs_)
        if (!moved[f] && !moved[g]) kept.emplace_back(f, g);
      pairs_ = with_moved_pairs(kept, S, B, moved);
    }
    tested_heights_ = heights;
    return pairs_;
  }

 private:
  OffsetPairCache* cache_;
  bool first_ = true;
  std::vector<std::pair<int, int>> pairs_;
  Eigen::VectorXd tested_heights_;
};

// Per base vertex: a corner of a face whose prism offends, with a flat or inverted tet or a
// boundary face meeting another (base-base pairs excepted: the base is given).
std::vector<char> offending_vertices(const MatrixX3d& S, const TetIndices& T, const MatrixX3i& F,
                                     const MatrixX3i& B,
                                     const std::vector<std::pair<int, int>>& pairs) {
  const int n = static_cast<int>(S.rows() / 2);
  std::vector<char> bad(n, 0);
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    if (flat_tet(S, T, t))
      for (int k = 0; k < 3; ++k) bad[F(t / 3, k) % n] = 1;
  for (const auto& [f, g] : pairs) {
    if (f < F.rows() && g < F.rows()) continue;  // both on the given base
    for (int k = 0; k < 3; ++k) {
      bad[B(f, k) % n] = 1;
      bad[B(g, k) % n] = 1;
    }
  }
  return bad;
}

// Halves the offending vertices' heights, not below the floor. Returns whether any moved;
// `stuck` counts those already at the floor.
bool lower_heights(const std::vector<char>& bad, double floor_h, Eigen::VectorXd& heights,
                   int& stuck) {
  bool progress = false;
  stuck = 0;
  for (size_t i = 0; i < bad.size(); ++i) {
    if (!bad[i]) continue;
    if (heights(i) > floor_h) {
      heights(i) = std::max(floor_h, 0.5 * heights(i));
      progress = true;
    } else {
      ++stuck;
    }
  }
  return progress;
}

// Grades the heights: none more than twice its lowest neighbour's, so a lowered region tapers
// off over a few rings instead of leaving a step; heights only decrease.
void grade_heights(const Adjacency& vv, Eigen::VectorXd& heights) {
  const int n = static_cast<int>(heights.size());
  for (bool changed = true; changed;) {
    changed = false;
    for (int i = 0; i < n; ++i) {
      for (const int* j = vv.begin(i); j != vv.end(i); ++j) {
        if (heights(i) > 2.0 * heights(*j)) {
          heights(i) = 2.0 * heights(*j);
          changed = true;
        }
      }
    }
  }
}

// The prisms that offend, ascending: those with a flat or inverted tet, and those whose
// offset or side wall meets another boundary face (a base face only offends through the other
// face of its pair: the base is given).
std::vector<int> offending_prisms(const MatrixX3d& S, const TetIndices& T, const MatrixX3i& F,
                                  const MatrixX3i& B,
                                  const std::vector<std::pair<int, int>>& pairs) {
  const int n = static_cast<int>(S.rows() / 2);
  std::vector<char> prism(static_cast<size_t>(F.rows()), 0);
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    if (flat_tet(S, T, t)) prism[static_cast<size_t>(t / 3)] = 1;
  const EdgeTopology topo = edge_topology(F, n);
  std::map<std::pair<int, int>, int> boundary_face;  // boundary edge (a < b) -> its face
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int e = topo.FE(f, k);
      if (topo.edge_faces.degree(e) == 1)
        boundary_face[{topo.E(e, 0), topo.E(e, 1)}] = static_cast<int>(f);
    }
  const auto prism_of = [&](int row) {
    if (row < 2 * F.rows()) return row % static_cast<int>(F.rows());
    // A side wall: the face on its boundary edge (its two base corners, modulo n).
    int a = -1, b = -1;
    for (int k = 0; k < 3; ++k) {
      const int v = B(row, k) % n;
      if (a < 0)
        a = v;
      else if (v != a)
        b = v;
    }
    const auto it = boundary_face.find({std::min(a, b), std::max(a, b)});
    return it == boundary_face.end() ? -1 : it->second;
  };
  for (const auto& [f, g] : pairs) {
    if (f < F.rows() && g < F.rows()) continue;
    for (const int row : {f, g})
      if (row >= F.rows()) {
        const int q = prism_of(row);
        if (q >= 0) prism[static_cast<size_t>(q)] = 1;
      }
  }
  std::vector<int> faces;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (prism[static_cast<size_t>(f)]) faces.push_back(static_cast<int>(f));
  return faces;
}

// The faces round the fold vertices of a failure, ascending.
void list_fold_faces(const MatrixX3i& F, int n, OffsetFailure& failure) {
  failure.fold = true;
  const Adjacency vf = vertex_faces(F, n);
  for (const int v : failure.vertices)
    failure.faces.insert(failure.faces.end(), vf.begin(v), vf.end(v));
  std::sort(failure.faces.begin(), failure.faces.end());
  failure.faces.erase(std::unique(failure.faces.begin(), failure.faces.end()), failure.faces.end());
}

// Every vertex a face uses starts at the full height; the others get no direction.
void start_heights(const MatrixX3i& F, double height, OffsetSurface& out) {
  const int n = static_cast<int>(out.directions.rows());
  std::vector<char> used(n, 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[F(f, k)] = 1;
  out.heights = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    if (used[i]) {
      out.heights(i) = height;
    } else {
      out.directions.row(i).setZero();
    }
  }
}

}  // namespace

void OffsetOptions::validate_smoothing() const {
  MQ_CHECK(smoothing_iterations >= 0, InvalidInput,
           "offset surface: smoothing_iterations must be >= 0, got ", smoothing_iterations);
  MQ_CHECK(std::isfinite(smoothing_radius) && smoothing_radius >= 0, InvalidInput,
           "offset surface: smoothing_radius must be finite and >= 0, got ", smoothing_radius);
}

void OffsetOptions::validate() const {
  MQ_CHECK(std::isfinite(height) && height > 0.0, InvalidInput,
           "offset surface: height must be finite and > 0, got ", height);
  MQ_CHECK(min_fraction > 0.0 && min_fraction <= 1.0, InvalidInput,
           "offset surface: min_fraction must lie in (0, 1], got ", min_fraction);
  MQ_CHECK(max_rounds >= 1, InvalidInput, "offset surface: max_rounds must be >= 1");
  validate_smoothing();
}

std::vector<int> fold_vertices(const MatrixX3d& V, const MatrixX3i& F) {
  MQ_CHECK(F.rows() == 0 || (F.minCoeff() >= 0 && F.maxCoeff() < V.rows()), InvalidInput,
           "fold vertices: face index out of range");
  std::vector<int> bad;
  std::string message;
  smoothed_directions(V, F, 0, bad, message);
  return bad;
}

MatrixX3d displacement_directions(const MatrixX3d& V, const MatrixX3i& F, double height) {
  OffsetOptions o;
  o.height = height;
  try {
    return offset_directions(V, F, o);
  } catch (const TopologyError&) {
    return vertex_normals(V, F);
  }
}

MatrixX3d offset_directions(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options,
                            int* steps_out) {
  const int steps = diffusion_steps(V, F, options);
  if (steps_out) *steps_out = steps;
  std::vector<int> bad;
  std::string message;
  MatrixX3d D = smoothed_directions(V, F, steps, bad, message);
  MQ_CHECK(bad.empty(), TopologyError, message);
  return D;
}

bool try_offset_surface(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options,
                        OffsetSurface& out, OffsetFailure& failure, OffsetPairCache* cache) {
  failure = OffsetFailure();
  options.validate();
  MQ_CHECK(V.allFinite(), InvalidInput, "offset surface: vertices contain NaN or infinite values");
  MQ_CHECK(F.rows() > 0, InvalidInput, "offset surface: the base has no faces");
  const int n = static_cast<int>(V.rows());
  const TetIndices T = shell_tet_indices(F, n);  // validates F
  const MatrixX3i B = shell_boundary_faces(F, n);
  const Adjacency vv = vertex_adjacency(F, n);

  out = OffsetSurface();
  out.smoothing_steps = diffusion_steps(V, F, options);
  out.directions = smoothed_directions(V, F, out.smoothing_steps, failure.vertices, failure.reason);
  if (!failure.vertices.empty()) {
    list_fold_faces(F, n, failure);
    return false;
  }
  start_heights(F, options.height, out);
  const double floor_h = options.min_fraction * options.height;
  MatrixX3d S(2 * n, 3);  // shell vertices: base then offset
  S.topRows(n) = V;
  ShellPairs shell_pairs(cache);
  for (int round = 0;; ++round) {
    out.V = V + out.heights.asDiagonal() * out.directions;
    S.bottomRows(n) = out.V;
    const std::vector<std::pair<int, int>>& pairs = shell_pairs.update(S, B, n, out.heights);
    const std::vector<char> bad = offending_vertices(S, T, F, B, pairs);
    if (std::find(bad.begin(), bad.end(), 1) == bad.end()) break;
    int stuck = 0;
    const bool progress = lower_heights(bad, floor_h, out.heights, stuck);
    if (!progress || round + 1 >= options.max_rounds) {
      failure.reason = detail::concat("offset surface: cannot make a valid shell (", stuck,
                                      " offending vertices already at the minimum height ", floor_h,
                                      " after ", round + 1, " rounds)");
      // Where it is stuck: the offending vertices at the floor (all of them when the rounds
      // ran out first), and the prisms that offend.
      for (int i = 0; i < n; ++i)
        if (bad[i] && (out.heights(i) <= floor_h || progress)) failure.vertices.push_back(i);
      failure.faces = offending_prisms(S, T, F, B, pairs);
      return false;
    }
    grade_heights(vv, out.heights);
  }
  return true;
}

OffsetSurface offset_surface(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options) {
  OffsetSurface out;
  OffsetFailure failure;
  MQ_CHECK(try_offset_surface(V, F, options, out, failure), TopologyError, failure.reason);
  return out;
}

}  // namespace mq
