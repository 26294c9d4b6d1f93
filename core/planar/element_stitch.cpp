#include "core/planar/element_stitch.h"

#include <algorithm>

#include "core/common/errors.h"
#include "core/mesh/boundary_loops.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

namespace {

struct Loop {
  std::vector<int> vertices;  // in merged-mesh numbering, following the faces' orientation
  Vector3d centroid = Vector3d::Zero();
  Vector3d vector_area = Vector3d::Zero();  // its direction gives the winding sense
};

std::vector<Loop> describe_loops(const MatrixX3d& V, const MatrixX3i& F, int offset) {
  std::vector<Loop> loops;
  for (std::vector<int>& raw : boundary_loops(F, static_cast<int>(V.rows()))) {
    Loop loop;
    for (int& v : raw) {
      loop.centroid += V.row(v).transpose();
      v += offset;
    }
    loop.centroid /= static_cast<double>(raw.size());
    for (size_t i = 0; i < raw.size(); ++i) {
      const Vector3d p = V.row(raw[i] - offset).transpose() - loop.centroid;
      const Vector3d q = V.row(raw[(i + 1) % raw.size()] - offset).transpose() - loop.centroid;
      loop.vector_area += 0.5 * p.cross(q);
    }
    loop.vertices = std::move(raw);
    loops.push_back(std::move(loop));
  }
  return loops;
}

// The two sides of a seam wind in opposite senses when both parts are oriented alike.
bool compatible(const Loop& a, const Loop& b) { return a.vector_area.dot(b.vector_area) <= 0; }

// Index of the loop of `others` whose centroid is nearest to `loop` (the first on ties), or -1.
int nearest_loop(const Loop& loop, const std::vector<Loop>& others) {
  int best = -1;
  double best_d = 0;
  for (size_t i = 0; i < others.size(); ++i) {
    const double d = (loop.centroid - others[i].centroid).squaredNorm();
    if (best < 0 || d < best_d) {
      best = static_cast<int>(i);
      best_d = d;
    }
  }
  return best;
}

Vector3d row(const MatrixX3d& V, int i) { return V.row(i).transpose(); }

// Zipper strip between loop a (walked backwards) and loop b (walked forwards), appended to F.
// Positions in a and b of the closest pair of vertices between the two loops.
std::pair<int, int> closest_pair(const MatrixX3d& V, const std::vector<int>& a,
                                 const std::vector<int>& b) {
  int p = 0, q = 0;
  double best = -1;
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j) {
      const double d = (row(V, a[i]) - row(V, b[j])).squaredNorm();
      if (best < 0 || d < best) {
        best = d;
        p = static_cast<int>(i);
        q = static_cast<int>(j);
      }
    }
  return {p, q};
}

// When the two loops have the same length and lie on each other vertex for vertex (the seams of
// a periodic swatch placed exactly), returns for each position k of b the vertex of a it
// coincides with; else an empty vector.
std::vector<int> weld_map(const MatrixX3d& V, const std::vector<int>& a, const std::vector<int>& b,
                          double tolerance) {
  const int n = static_cast<int>(a.size());
  if (n != static_cast<int>(b.size()) || tolerance <= 0) return {};
  const auto [p, q] = closest_pair(V, a, b);
  std::vector<int> map(n);
  for (int k = 0; k < n; ++k) {
    const int ia = a[(p - k + n) % n], jb = (q + k) % n;
    if ((row(V, ia) - row(V, b[jb])).norm() > tolerance) return {};
    map[jb] = ia;
  }
  return map;
}

void bridge(const MatrixX3d& V, const std::vector<int>& a, const std::vector<int>& b,
            std::vector<Eigen::Vector3i>& faces) {
  const int n = static_cast<int>(a.size()), m = static_cast<int>(b.size());
  auto [p, q] = closest_pair(V, a, b);
  for (int done_a = 0, done_b = 0; done_a < n || done_b < m;) {
    // n, m > 0: the caller bridges two boundary loops.
    // NOLINTNEXTLINE(clang-analyzer-core.DivideZero)
    const int ap = a[p], a_prev = a[(p + n - 1) % n], bq = b[q], b_next = b[(q + 1) % m];
    bool advance_a = done_b == m;
    if (done_a < n && done_b < m)
      advance_a = (row(V, a_prev) - row(V, bq)).squaredNorm() <=
                  (row(V, ap) - row(V, b_next)).squaredNorm();
    if (advance_a) {
      faces.emplace_back(ap, a_prev, bq);  // uses a_prev -> ap reversed
      p = (p + n - 1) % n;
      ++done_a;
    } else {
      faces.emplace_back(ap, b_next, bq);  // uses bq -> b_next reversed
      q = (q + 1) % m;
      ++done_b;
    }
  }
}

// Closest point to x on the closed polyline through `loop`.
Vector3d closest_on_loop(const MatrixX3d& V, const std::vector<int>& loop, const Vector3d& x) {
  Vector3d best = row(V, loop[0]);
  double best_d = (best - x).squaredNorm();
  for (size_t i = 0; i < loop.size(); ++i) {
    const Vector3d p = row(V, loop[i]), q = row(V, loop[(i + 1) % loop.size()]);
    const Vector3d d = q - p;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::clamp((x - p).dot(d) / len2, 0.0, 1.0) : 0.0;
    const Vector3d c = p + t * d;
    const double dist = (c - x).squaredNorm();
    if (dist < best_d) {
      best_d = dist;
      best = c;
    }
  }
  return best;
}

}  // namespace

std::optional<StitchResult> stitch_cut_elements(const TriMesh& A, const TriMesh& B,
                                                const StitchOptions& options) {
  MQ_CHECK(A.V.allFinite() && B.V.allFinite(), InvalidInput,
           "stitch_cut_elements: a vertex has a non-finite coordinate");
  MQ_CHECK(options.max_loop_distance >= 0, InvalidInput,
           "stitch_cut_elements: max_loop_distance is negative or NaN");
  StitchResult result;
  result.mesh = A;
  append_mesh(result.mesh, B);
  const MatrixX3d& V = result.mesh.V;
  const std::vector<Loop> loops_a = describe_loops(A.V, A.F, 0);
  const std::vector<Loop> loops_b = describe_loops(B.V, B.F, A.num_vertices());

  std::vector<Eigen::Vector3i> bridge_faces;
  std::vector<int> replace(V.rows());
  for (int v = 0; v < V.rows(); ++v) replace[v] = v;
  for (size_t i = 0; i < loops_a.size(); ++i) {
    const int j = nearest_loop(loops_a[i], loops_b);
    if (j < 0 || nearest_loop(loops_b[j], loops_a) != static_cast<int>(i)) continue;
    if (!compatible(loops_a[i], loops_b[j])) continue;
    if (!((loops_a[i].centroid - loops_b[j].centroid).norm() <= options.max_loop_distance))
      continue;
    const Loop& la = loops_a[i];
    const Loop& lb = loops_b[j];
    const std::vector<int> welded = weld_map(V, la.vertices, lb.vertices, options.weld_tolerance);
    if (!welded.empty()) {
      // Coincident seams are glued vertex to vertex: b's loop vertices are replaced by a's.
      for (size_t k = 0; k < welded.size(); ++k) {
        replace[lb.vertices[k]] = welded[k];
        result.constraints.push_back(
            LinearConstraint::point(welded[k], 0.5 * (row(V, welded[k]) + row(V, lb.vertices[k]))));
      }
      ++result.bridged_loops;
      continue;
    }
    bridge(V, la.vertices, lb.vertices, bridge_faces);
    // Section 2.7 pulls both seams towards their averaged points. Only the part of the offset
    // across the seam direction (the loops' normal) is averaged: averaging the part along it
    // too would collapse the bridge strip to zero width.
    Vector3d axis = la.vector_area - lb.vector_area;
    axis = axis.norm() > 0 ? Vector3d(axis.normalized()) : Vector3d::Zero();
    auto lateral_target = [&](int v, const std::vector<int>& other) {
      const Vector3d x = row(V, v);
      const Vector3d d = closest_on_loop(V, other, x) - x;
      return Vector3d(x + 0.5 * (d - d.dot(axis) * axis));
    };
    for (int v : la.vertices)
      result.constraints.push_back(LinearConstraint::point(v, lateral_target(v, lb.vertices)));
    for (int v : lb.vertices)
      result.constraints.push_back(LinearConstraint::point(v, lateral_target(v, la.vertices)));
    ++result.bridged_loops;
  }
  if (result.bridged_loops == 0) return std::nullopt;

  MatrixX3i& F = result.mesh.F;
  const Eigen::Index old_rows = F.rows();
  F.conservativeResize(old_rows + static_cast<Eigen::Index>(bridge_faces.size()), 3);
  for (size_t k = 0; k < bridge_faces.size(); ++k)
    F.row(old_rows + static_cast<Eigen::Index>(k)) = bridge_faces[k].transpose();
  // Apply the welds and drop the vertices they made unused, renumbering the constraints.
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) F(f, k) = replace[F(f, k)];
  std::vector<int> index(V.rows(), -1);
  int count = 0;
  for (int v = 0; v < V.rows(); ++v)
    if (replace[v] == v) {
      index[v] = count++;
      result.origin.push_back(v);
    }
  if (count < V.rows()) {
    MatrixX3d W(count, 3);
    for (int v = 0; v < V.rows(); ++v)
      if (index[v] >= 0) W.row(index[v]) = V.row(v);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) F(f, k) = index[F(f, k)];
    for (LinearConstraint& c : result.constraints) c.vertices[0] = index[c.vertices[0]];
    result.mesh.V = std::move(W);
    result.mesh.N.resize(0, 3);
  }
  std::vector<int> face_component;
  if (connected_components(F, result.mesh.num_vertices(), face_component) != 1) return std::nullopt;
  return result;
}

}  // namespace mq
