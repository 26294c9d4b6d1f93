#include "core/offset_surface.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

#include "core/errors.h"
#include "core/geometry_measures.h"
#include "core/mesh_intersections.h"
#include "core/mesh_topology.h"
#include "core/shell_tetrahedra.h"

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

// Laplacian diffusion of the normals, refusing steps that leave a vertex's face cone.
MatrixX3d smoothed_directions(const MatrixX3d& V, const MatrixX3i& F, int iterations) {
  const int n = static_cast<int>(V.rows());
  const MatrixX3d FN = face_normals(V, F);
  const Adjacency vv = vertex_adjacency(F, n);
  const Adjacency vf = vertex_faces(F, n);
  MatrixX3d D = vertex_normals(V, F);
  for (int i = 0; i < n; ++i) {
    MQ_CHECK(vf.degree(i) == 0 || D.row(i).squaredNorm() > 0.5, TopologyError,
             "offset surface: vertex ", i, " has no normal (its faces cancel)");
    if (vf.degree(i) == 0 || min_face_cosine(D.row(i), FN, vf, i) >= kMinCosine) continue;
    D.row(i) = cone_direction(D.row(i), FN, vf, i);
    MQ_CHECK(min_face_cosine(D.row(i), FN, vf, i) > 0.0, TopologyError, "offset surface: vertex ",
             i, " (", V(i, 0), " ", V(i, 1), " ", V(i, 2),
             ") has no direction above all its faces (the base folds there), so no valid "
             "shell prism exists at any height");
  }
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

}  // namespace

MatrixX3d offset_directions(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options,
                            int* steps_out) {
  MQ_CHECK(options.smoothing_iterations >= 0, InvalidInput,
           "offset surface: smoothing_iterations must be >= 0, got ", options.smoothing_iterations);
  MQ_CHECK(std::isfinite(options.smoothing_radius) && options.smoothing_radius >= 0, InvalidInput,
           "offset surface: smoothing_radius must be finite and >= 0, got ",
           options.smoothing_radius);
  int steps = options.smoothing_iterations;
  const double mean_edge = mean_edge_length(V, F);
  if (mean_edge > 0 && std::isfinite(options.height)) {
    const double reach = options.smoothing_radius * options.height / mean_edge;
    // Bounded: past 10^4 steps the reach is far beyond any shell (the base is degenerate).
    steps = std::max(steps, static_cast<int>(std::ceil(std::min(reach * reach, 1e4))));
  }
  if (steps_out) *steps_out = steps;
  return smoothed_directions(V, F, steps);
}

OffsetSurface offset_surface(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options) {
  MQ_CHECK(std::isfinite(options.height) && options.height > 0.0, InvalidInput,
           "offset surface: height must be finite and > 0, got ", options.height);
  MQ_CHECK(options.min_fraction > 0.0 && options.min_fraction <= 1.0, InvalidInput,
           "offset surface: min_fraction must lie in (0, 1], got ", options.min_fraction);
  MQ_CHECK(options.max_rounds >= 1, InvalidInput, "offset surface: max_rounds must be >= 1");
  MQ_CHECK(V.allFinite(), InvalidInput, "offset surface: vertices contain NaN or infinite values");
  MQ_CHECK(F.rows() > 0, InvalidInput, "offset surface: the base has no faces");
  const int n = static_cast<int>(V.rows());
  const TetIndices T = shell_tet_indices(F, n);  // validates F
  const MatrixX3i B = shell_boundary_faces(F, n);
  const Adjacency vv = vertex_adjacency(F, n);

  OffsetSurface out;
  out.directions = offset_directions(V, F, options, &out.smoothing_steps);
  std::vector<char> used(n, 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[F(f, k)] = 1;
  out.heights = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    if (used[i]) {
      out.heights(i) = options.height;
    } else {
      out.directions.row(i).setZero();
    }
  }
  const double floor_h = options.min_fraction * options.height;

  IntersectionOptions all_pairs;
  all_pairs.between_components_only = false;
  MatrixX3d S(2 * n, 3);  // shell vertices: base then offset
  S.topRows(n) = V;
  // Intersecting boundary pairs of the last round. A round re-tests only the pairs with a face
  // that moved (an offset vertex lowered): the others keep last round's answer, so every round
  // sees exactly the pairs a full test would, at the cost of the faces that moved (on a 1.1M-
  // face base the full test every round was most of the shell's cost).
  std::vector<std::pair<int, int>> pairs;
  Eigen::VectorXd tested_heights;
  for (int round = 0;; ++round) {
    out.V = V + out.heights.asDiagonal() * out.directions;
    S.bottomRows(n) = out.V;

    std::vector<char> bad(n, 0);
    bool any_bad = false;
    auto mark = [&](int v) {
      bad[v % n] = 1;
      any_bad = true;
    };
    for (Eigen::Index t = 0; t < T.rows(); ++t) {
      const Vector3d p[4] = {S.row(T(t, 0)), S.row(T(t, 1)), S.row(T(t, 2)), S.row(T(t, 3))};
      double l2 = 0.0;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) l2 = std::max(l2, (p[a] - p[b]).squaredNorm());
      if (!(tet_volume(p[0], p[1], p[2], p[3]) > kMinRelativeVolume * l2 * std::sqrt(l2)))
        for (int k = 0; k < 3; ++k) mark(F(t / 3, k));
    }
    if (round == 0) {
      pairs = intersecting_face_pairs(S, B, all_pairs);
    } else {
      std::vector<char> moved(static_cast<size_t>(B.rows()), 0);
      for (Eigen::Index f = 0; f < B.rows(); ++f)
        for (int k = 0; k < 3; ++k) {
          const int v = B(f, k);
          if (v >= n && out.heights(v - n) != tested_heights(v - n)) moved[f] = 1;
        }
      std::vector<std::pair<int, int>> kept;
      for (const auto& [f, g] : pairs)
        if (!moved[f] && !moved[g]) kept.emplace_back(f, g);
      std::vector<std::pair<int, int>> fresh = intersecting_face_pairs_touching(S, B, moved);
      pairs.clear();
      std::merge(kept.begin(), kept.end(), fresh.begin(), fresh.end(), std::back_inserter(pairs));
    }
    tested_heights = out.heights;
    for (const auto& [f, g] : pairs) {
      if (f < F.rows() && g < F.rows()) continue;  // both on the given base
      for (int k = 0; k < 3; ++k) {
        mark(B(f, k));
        mark(B(g, k));
      }
    }
    if (!any_bad) break;

    bool progress = false;
    int stuck = 0;
    for (int i = 0; i < n; ++i) {
      if (!bad[i]) continue;
      if (out.heights(i) > floor_h) {
        out.heights(i) = std::max(floor_h, 0.5 * out.heights(i));
        progress = true;
      } else {
        ++stuck;
      }
    }
    MQ_CHECK(progress && round + 1 < options.max_rounds, TopologyError,
             "offset surface: cannot make a valid shell (", stuck,
             " offending vertices already at the minimum height ", floor_h, " after ", round + 1,
             " rounds)");
    // Grade the heights: none more than twice its lowest neighbour's, so a lowered region
    // tapers off over a few rings instead of leaving a step; heights only decrease.
    for (bool changed = true; changed;) {
      changed = false;
      for (int i = 0; i < n; ++i) {
        for (const int* j = vv.begin(i); j != vv.end(i); ++j) {
          if (out.heights(i) > 2.0 * out.heights(*j)) {
            out.heights(i) = 2.0 * out.heights(*j);
            changed = true;
          }
        }
      }
    }
  }
  return out;
}

}  // namespace mq
