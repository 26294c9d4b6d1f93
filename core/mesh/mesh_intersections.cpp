#include "core/mesh/mesh_intersections.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

#include "core/common/errors.h"
#include "core/mesh/flat_stars.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"

namespace mq {
namespace {

int sign(double x) { return (x > 0) - (x < 0); }

// Sign of det[b-a, c-a, d-a]: positive when d lies on the side of plane abc that its
// counter-clockwise normal points to.
int orient3d(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  return sign((b - a).cross(c - a).dot(d - a));
}

int orient2d(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return sign((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
}

// Is c, known collinear with segment ab, within its bounding box (hence on the segment)?
bool on_segment(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= c.y() && c.y() <= std::max(a.y(), b.y());
}

bool segments_intersect_2d(const Vector2d& p1, const Vector2d& p2, const Vector2d& q1,
                           const Vector2d& q2) {
  const int d1 = orient2d(p1, p2, q1), d2 = orient2d(p1, p2, q2);
  const int d3 = orient2d(q1, q2, p1), d4 = orient2d(q1, q2, p2);
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  return (d1 == 0 && on_segment(p1, p2, q1)) || (d2 == 0 && on_segment(p1, p2, q2)) ||
         (d3 == 0 && on_segment(q1, q2, p1)) || (d4 == 0 && on_segment(q1, q2, p2));
}

// Closed point-in-triangle test; the triangle may have either orientation.
bool point_in_triangle_2d(const Vector2d& p, const Vector2d& a, const Vector2d& b,
                          const Vector2d& c) {
  const int s1 = orient2d(a, b, p), s2 = orient2d(b, c, p), s3 = orient2d(c, a, p);
  const bool has_neg = s1 < 0 || s2 < 0 || s3<0, has_pos = s1> 0 || s2 > 0 || s3 > 0;
  return !(has_neg && has_pos);
}

// Index of the axis dropped when projecting onto the plane with normal n.
int dominant_axis(const Vector3d& n) {
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  return k;
}

Vector2d project(const Vector3d& p, int drop) {
  return drop == 0   ? Vector2d(p.y(), p.z())
         : drop == 1 ? Vector2d(p.z(), p.x())
                     : Vector2d(p.x(), p.y());
}

// Plane normal for the coplanar tests: of the first triangle, or the second if it is degenerate.
int coplanar_axis(const Vector3d& a0, const Vector3d& a1, const Vector3d& a2, const Vector3d& b0,
                  const Vector3d& b1, const Vector3d& b2) {
  Vector3d n = (a1 - a0).cross(a2 - a0);
  if (n.squaredNorm() == 0) n = (b1 - b0).cross(b2 - b0);
  return dominant_axis(n);
}

bool coplanar_triangles_intersect(const std::array<Vector2d, 3>& a,
                                  const std::array<Vector2d, 3>& b) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (segments_intersect_2d(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])) return true;
  return point_in_triangle_2d(a[0], b[0], b[1], b[2]) ||
         point_in_triangle_2d(b[0], a[0], a[1], a[2]);
}

// (b - a) x (c - a): orient3d(a, b, c, d) is the sign of its dot product with d - a, computed
// once per triangle instead of once per point (the same arithmetic, so the same signs).
Vector3d plane_normal(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  return (b - a).cross(c - a);
}

// Closed segment pq against closed triangle abc, n its plane_normal.
bool segment_triangle_intersect(const Vector3d& p, const Vector3d& q, const Vector3d& a,
                                const Vector3d& b, const Vector3d& c, const Vector3d& n) {
  const int op = sign(n.dot(p - a)), oq = sign(n.dot(q - a));
  if (op * oq > 0) return false;
  // The predicates are not exact: a segment in a tilted plane with the triangle (the fan that
  // caps a thread's end) gets signs from rounding, and the line test below then reports
  // sectors of the fan on opposite sides of its centre as overlapping. Within a relative 1e-9
  // of the plane the segment is taken to lie in it.
  const double tolerance =
      1e-9 * n.norm() * std::max({(q - p).norm(), (b - a).norm(), (c - a).norm(), (c - b).norm()});
  const bool in_plane = (op == 0 && oq == 0) || (std::abs(n.dot(p - a)) <= tolerance &&
                                                 std::abs(n.dot(q - a)) <= tolerance);
  if (in_plane) {  // segment in the triangle's plane
    const int k = dominant_axis(n);
    const Vector2d p2 = project(p, k), q2 = project(q, k);
    const Vector2d a2 = project(a, k), b2 = project(b, k), c2 = project(c, k);
    return point_in_triangle_2d(p2, a2, b2, c2) || segments_intersect_2d(p2, q2, a2, b2) ||
           segments_intersect_2d(p2, q2, b2, c2) || segments_intersect_2d(p2, q2, c2, a2);
  }
  // The segment meets the plane in one point; it is in the triangle iff the line pq passes
  // on the same side of all three edges.
  const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  const bool has_neg = s1 < 0 || s2 < 0 || s3<0, has_pos = s1> 0 || s2 > 0 || s3 > 0;
  return !(has_neg && has_pos);
}

bool segment_triangle_intersect(const Vector3d& p, const Vector3d& q, const Vector3d& a,
                                const Vector3d& b, const Vector3d& c) {
  return segment_triangle_intersect(p, q, a, b, c, plane_normal(a, b, c));
}

// Face pair test with combinatorial sharing taken into account (see IntersectionOptions).
// flat (optional, #V): flat_stars' verdicts; two faces sharing only a vertex whose star is flat
// meet only there.
bool faces_intersect(const MatrixX3d& V, const MatrixX3i& F, int f, int g,
                     const std::vector<char>* flat = nullptr) {
  std::array<int, 3> shared_f{}, shared_g{};
  int num_shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (F(f, i) == F(g, j)) {
        shared_f[num_shared] = i;
        shared_g[num_shared] = j;
        ++num_shared;
      }
  const auto P = [&](int face, int k) -> Vector3d { return V.row(F(face, k)).transpose(); };
  if (num_shared == 0)
    return triangles_intersect(P(f, 0), P(f, 1), P(f, 2), P(g, 0), P(g, 1), P(g, 2));
  if (num_shared >= 3) return true;  // duplicated face
  if (num_shared == 2) {
    // Non-coplanar faces sharing an edge meet only along it; coplanar ones overlap iff
    // their opposite vertices lie on the same side of the edge (a fold-over).
    const int u = shared_f[0], v = shared_f[1];
    const int a = 3 - u - v, b = 3 - shared_g[0] - shared_g[1];
    // Coplanar within the same relative 1e-9 as segment_triangle_intersect's.
    const Vector3d n = (P(f, v) - P(f, u)).cross(P(f, a) - P(f, u));
    const double scale = std::max(
        {(P(f, v) - P(f, u)).norm(), (P(f, a) - P(f, u)).norm(), (P(g, b) - P(f, u)).norm()});
    if (std::abs(n.dot(P(g, b) - P(f, u))) > 1e-9 * n.norm() * scale) return false;
    const int k = dominant_axis((P(f, 1) - P(f, 0)).cross(P(f, 2) - P(f, 0)));
    const Vector2d u2 = project(P(f, u), k), v2 = project(P(f, v), k);
    return orient2d(u2, v2, project(P(f, a), k)) * orient2d(u2, v2, project(P(g, b), k)) > 0;
  }
  // One shared vertex s: the (convex) intersection contains s, and it contains more iff the
  // edge opposite s of one face meets the other face; never when s's star is flat.
  if (flat && (*flat)[static_cast<size_t>(F(f, shared_f[0]))]) return false;
  const int fa = (shared_f[0] + 1) % 3, fb = (shared_f[0] + 2) % 3;
  const int ga = (shared_g[0] + 1) % 3, gb = (shared_g[0] + 2) % 3;
  return segment_triangle_intersect(P(f, fa), P(f, fb), P(g, 0), P(g, 1), P(g, 2)) ||
         segment_triangle_intersect(P(g, ga), P(g, gb), P(f, 0), P(f, 1), P(f, 2));
}

// body(b) for b in [0, blocks): in parallel, or inline for a small mesh (one element's test,
// mostly called from loops that are parallel already, where a task costs more than it saves).
template <class Body>
void each_block(int blocks, int num_faces, const Body& body) {
  if (num_faces <= 16384) {
    for (int b = 0; b < blocks; ++b) body(b);
    return;
  }
  tbb::parallel_for(0, blocks, body);
}

// What the narrow phase reads of a candidate, in one cache line: its box rounded outward to
// float (a quick, conservative rejection; the exact test decides), its first and last cells,
// its label.
struct FaceBox {
  float lo[3], hi[3];
  int c0[3], c1[3];
  int label;
};

// The broad phase: every face's FaceBox on a uniform grid whose cells are about the mean face
// box, and the faces bucketed by cell (with an active set only the active faces).
struct FaceGrid {
  std::vector<FaceBox> box;  // #F
  std::array<int, 3> n{};    // cells per axis
  std::vector<int> offsets;  // #cells + 1, into members
  std::vector<int> members;  // faces by cell, ascending in each
  int cell_index(int i, int j, int k) const { return (k * n[1] + j) * n[0] + i; }
};

// The boxes are made first (cells 0), in one pass that also sums their sizes and bounds per
// block (in block order: the same cell size whatever the threads); no double-precision box
// arrays (2 x 24 bytes a face, freshly mapped pages on every call). Returns the bounds and the
// summed size.
struct BoxSum {
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
  Vector3d hi = Vector3d::Constant(-std::numeric_limits<double>::infinity());
  double size = 0;
};

BoxSum candidate_boxes(const MatrixX3d& V, const MatrixX3i& F, const std::vector<int>* label,
                       std::vector<FaceBox>& box) {
  const int nf = static_cast<int>(F.rows());
  box.resize(static_cast<size_t>(nf));
  constexpr int kBoxBlock = 16384;
  std::vector<BoxSum> block_sum(static_cast<size_t>((nf + kBoxBlock - 1) / kBoxBlock));
  each_block(static_cast<int>(block_sum.size()), nf, [&](int b) {
    BoxSum& sum = block_sum[static_cast<size_t>(b)];
    for (int f = b * kBoxBlock, end = std::min(nf, f + kBoxBlock); f < end; ++f) {
      const Vector3d p0 = V.row(F(f, 0)), p1 = V.row(F(f, 1)), p2 = V.row(F(f, 2));
      const Vector3d lo = p0.cwiseMin(p1).cwiseMin(p2), hi = p0.cwiseMax(p1).cwiseMax(p2);
      sum.lo = sum.lo.cwiseMin(lo);
      sum.hi = sum.hi.cwiseMax(hi);
      sum.size += (hi - lo).maxCoeff();
      FaceBox& c = box[static_cast<size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        float l = static_cast<float>(lo[k]), u = static_cast<float>(hi[k]);
        if (static_cast<double>(l) > lo[k])
          l = std::nextafter(l, -std::numeric_limits<float>::infinity());
        if (static_cast<double>(u) < hi[k])
          u = std::nextafter(u, std::numeric_limits<float>::infinity());
        c.lo[k] = l;
        c.hi[k] = u;
      }
      c.label = label ? (*label)[static_cast<size_t>(f)] : 0;
    }
  });
  BoxSum all;
  for (const BoxSum& b : block_sum) {
    all.lo = all.lo.cwiseMin(b.lo);
    all.hi = all.hi.cwiseMax(b.hi);
    all.size += b.size;
  }
  return all;
}

FaceGrid face_grid(const MatrixX3d& V, const MatrixX3i& F, const std::vector<int>* label,
                   const std::vector<char>* active) {
  const int nf = static_cast<int>(F.rows());
  FaceGrid grid;
  std::vector<FaceBox>& box = grid.box;
  const BoxSum all = candidate_boxes(V, F, label, box);
  const Vector3d gmin = all.lo;
  const Vector3d gext = all.hi - all.lo;

  // Cell size: the mean face box size, enlarged if the grid would have too many cells.
  double h = all.size / nf;
  if (!(h > 0)) h = std::max(gext.maxCoeff(), 1.0);
  const double max_cells = 4.0 * nf + 64.0;
  std::array<int, 3>& n = grid.n;
  for (;;) {
    double cells = 1;
    for (int k = 0; k < 3; ++k) {
      n[k] = std::max(1, static_cast<int>(std::ceil(gext[k] / h)));
      cells *= n[k];
    }
    if (cells <= max_cells) break;
    h *= 1.25;
  }
  const auto cell_coord = [&](double x, int k) {
    return std::clamp(static_cast<int>(std::floor((x - gmin[k]) / h)), 0, n[k] - 1);
  };
  // The cells from the exact (double) box, as the grid's bounds are exact.
  constexpr int kBlock = 4096;
  each_block((nf + kBlock - 1) / kBlock, nf, [&](int b) {
    for (int f = b * kBlock, end = std::min(nf, f + kBlock); f < end; ++f) {
      const Vector3d p0 = V.row(F(f, 0)), p1 = V.row(F(f, 1)), p2 = V.row(F(f, 2));
      const Vector3d lo = p0.cwiseMin(p1).cwiseMin(p2), hi = p0.cwiseMax(p1).cwiseMax(p2);
      FaceBox& c = box[static_cast<size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        c.c0[k] = cell_coord(lo[k], k);
        c.c1[k] = cell_coord(hi[k], k);
      }
    }
  });

  // Bucket faces by cell (a counting sort). Serial: relaxed atomic increments from two threads
  // cost 4x more than the plain ones (chain mail on the ivy wall's shell, perf).
  const int num_cells = n[0] * n[1] * n[2];
  std::vector<int>& offsets = grid.offsets;
  offsets.assign(static_cast<size_t>(num_cells) + 1, 0);
  const auto each_cell = [&](int f, auto&& visit) {
    const FaceBox& c = box[static_cast<size_t>(f)];
    for (int k = c.c0[2]; k <= c.c1[2]; ++k)
      for (int j = c.c0[1]; j <= c.c1[1]; ++j)
        for (int i = c.c0[0]; i <= c.c1[0]; ++i) visit(grid.cell_index(i, j, k));
  };
  // With an active set only the active faces and the faces that share a cell with one: no other
  // pair has an active face (a shell update moves a few dozen of 356k faces).
  std::vector<char> take;
  if (active) {
    take.assign(static_cast<size_t>(nf), 0);
    std::vector<char> near(static_cast<size_t>(num_cells), 0);
    for (int f = 0; f < nf; ++f)
      if ((*active)[static_cast<size_t>(f)])
        each_cell(f, [&](int c) { near[static_cast<size_t>(c)] = 1; });
    for (int f = 0; f < nf; ++f)
      each_cell(f, [&](int c) { take[static_cast<size_t>(f)] |= near[static_cast<size_t>(c)]; });
  }
  const auto taken = [&](int f) { return !active || take[static_cast<size_t>(f)]; };
  for (int f = 0; f < nf; ++f)
    if (taken(f)) each_cell(f, [&](int c) { ++offsets[static_cast<size_t>(c) + 1]; });
  for (int c = 0; c < num_cells; ++c) offsets[c + 1] += offsets[c];
  grid.members.resize(static_cast<size_t>(offsets.back()));
  // offsets[c] serves as bucket c's cursor, and ends at bucket c + 1's start: shifted back after.
  for (int f = 0; f < nf; ++f)
    if (taken(f))
      each_cell(f, [&](int c) {
        grid.members[static_cast<size_t>(offsets[static_cast<size_t>(c)]++)] = f;
      });
  for (int c = num_cells; c > 0; --c) offsets[c] = offsets[c - 1];
  offsets[0] = 0;
  return grid;
}

// The narrow phase, cell by cell: every two faces bucketed in a cell whose boxes overlap, tested
// in the one cell that holds the min corner of their boxes' intersection, so each pair once. A
// cell's boxes are copied out once, instead of read by every face that shares the cell: scattered
// reads across the box array and a search in each bucket were most of the broad phase on chain
// mail (a bent 24 x 24 sheet, 664k faces: 0.83x the time by face). The exact test takes the
// active face first (the earlier if both are or there is no active set): it rounds asymmetrically.
// Pairs (f, g), f < g, in ascending order, whatever the threads.
std::vector<std::pair<int, int>> pairs_by_cell(const MatrixX3d& V, const MatrixX3i& F,
                                               const FaceGrid& grid, bool labelled, bool same_label,
                                               const std::vector<char>* active, bool stop_at_first,
                                               const std::vector<char>* flat) {
  const int num_cells = grid.n[0] * grid.n[1] * grid.n[2];
  constexpr int kCells = 4096;
  const int blocks = (num_cells + kCells - 1) / kCells;
  std::vector<std::vector<std::pair<int, int>>> found(static_cast<size_t>(blocks));
  std::atomic<bool> any{false};  // with stop_at_first: a pair found, every block stops
  each_block(blocks, static_cast<int>(F.rows()), [&](int block) {
    std::vector<std::pair<int, int>>& out = found[static_cast<size_t>(block)];
    std::vector<FaceBox> local;
    std::vector<char> on;
    for (int c = block * kCells, end = std::min(num_cells, c + kCells); c < end; ++c) {
      if (stop_at_first && any.load(std::memory_order_relaxed)) return;
      const int* const face = grid.members.data() + grid.offsets[static_cast<size_t>(c)];
      const auto n = static_cast<size_t>(grid.offsets[static_cast<size_t>(c) + 1] -
                                         grid.offsets[static_cast<size_t>(c)]);
      if (n < 2) continue;
      local.resize(n);
      on.resize(n);
      bool any_on = false;
      for (size_t x = 0; x < n; ++x) {
        local[x] = grid.box[static_cast<size_t>(face[x])];
        on[x] = !active || (*active)[static_cast<size_t>(face[x])];
        any_on = any_on || on[x];
      }
      if (!any_on) continue;
      const int i = c % grid.n[0], j = (c / grid.n[0]) % grid.n[1], k = c / (grid.n[0] * grid.n[1]);
      // Buckets are ascending: face[x] < face[y].
      for (size_t x = 0; x + 1 < n; ++x) {
        const FaceBox& a = local[x];
        for (size_t y = x + 1; y < n; ++y) {
          if (!on[x] && !on[y]) continue;
          const FaceBox& b = local[y];
          if (labelled && (a.label == b.label) != same_label) continue;
          if (a.lo[0] > b.hi[0] || b.lo[0] > a.hi[0] || a.lo[1] > b.hi[1] || b.lo[1] > a.hi[1] ||
              a.lo[2] > b.hi[2] || b.lo[2] > a.hi[2])
            continue;
          if (std::max(a.c0[0], b.c0[0]) != i || std::max(a.c0[1], b.c0[1]) != j ||
              std::max(a.c0[2], b.c0[2]) != k)
            continue;
          if (on[x] ? faces_intersect(V, F, face[x], face[y], flat)
                    : faces_intersect(V, F, face[y], face[x], flat)) {
            out.emplace_back(face[x], face[y]);
            if (stop_at_first) {
              any.store(true, std::memory_order_relaxed);
              return;
            }
          }
        }
      }
    }
  });
  std::vector<std::pair<int, int>> result;
  for (const auto& block : found) result.insert(result.end(), block.begin(), block.end());
  std::sort(result.begin(), result.end());
  return result;
}

// Shared implementation: when label is given, only pairs with different labels are tested, or
// with same_label only pairs with the same label.
// active (optional, #F): only pairs with at least one active face are tested.
std::vector<std::pair<int, int>> find_pairs(const MatrixX3d& V, const MatrixX3i& F,
                                            const std::vector<int>* label, bool stop_at_first,
                                            bool same_label = false,
                                            const std::vector<char>* active = nullptr) {
  if (F.rows() == 0) return {};
  MQ_CHECK(V.allFinite(), InvalidInput, "intersection test: vertex positions are not finite");
  MQ_CHECK(F.minCoeff() >= 0 && F.maxCoeff() < V.rows(), InvalidInput,
           "intersection test: face index out of range [0, ", V.rows(), ")");
  // Faces sharing a vertex are tested only when the labels let faces of one component meet;
  // with an active set every pair has an active face, whose vertex any shared one is. A few
  // active faces have too few such pairs to pay for the stars' pass over the faces.
  std::vector<char> flat;
  const auto num_active =
      active ? std::count_if(active->begin(), active->end(), [](char a) { return a != 0; })
             : static_cast<std::ptrdiff_t>(F.rows());
  if ((!label || same_label) && 8 * num_active >= F.rows()) {
    std::vector<char> needed;
    if (active) {
      needed.assign(static_cast<size_t>(V.rows()), 0);
      for (Eigen::Index f = 0; f < F.rows(); ++f)
        if ((*active)[static_cast<size_t>(f)])
          for (int k = 0; k < 3; ++k) needed[static_cast<size_t>(F(f, k))] = 1;
    }
    flat = flat_stars(V, F, active ? &needed : nullptr);
  }
  std::vector<std::pair<int, int>> result =
      pairs_by_cell(V, F, face_grid(V, F, label, active), label != nullptr, same_label, active,
                    stop_at_first, flat.empty() ? nullptr : &flat);
  if (stop_at_first && result.size() > 1) result.resize(1);
  return result;
}

}  // namespace

bool triangles_intersect(const Vector3d& a0, const Vector3d& a1, const Vector3d& a2,
                         const Vector3d& b0, const Vector3d& b1, const Vector3d& b2) {
  // Separating planes: all of one triangle strictly on one side of the other's plane.
  const Vector3d nb = plane_normal(b0, b1, b2);
  const int da0 = sign(nb.dot(a0 - b0)), da1 = sign(nb.dot(a1 - b0)), da2 = sign(nb.dot(a2 - b0));
  if ((da0 > 0 && da1 > 0 && da2 > 0) || (da0 < 0 && da1 < 0 && da2 < 0)) return false;
  const Vector3d na = plane_normal(a0, a1, a2);
  const int db0 = sign(na.dot(b0 - a0)), db1 = sign(na.dot(b1 - a0)), db2 = sign(na.dot(b2 - a0));
  if ((db0 > 0 && db1 > 0 && db2 > 0) || (db0 < 0 && db1 < 0 && db2 < 0)) return false;
  if ((da0 == 0 && da1 == 0 && da2 == 0) || (db0 == 0 && db1 == 0 && db2 == 0)) {
    const int k = coplanar_axis(a0, a1, a2, b0, b1, b2);
    return coplanar_triangles_intersect({project(a0, k), project(a1, k), project(a2, k)},
                                        {project(b0, k), project(b1, k), project(b2, k)});
  }
  // Non-coplanar: both meet the line of the two planes in an interval; the intervals overlap
  // iff an endpoint of one, which lies on an edge of its triangle, is inside the other.
  return segment_triangle_intersect(a0, a1, b0, b1, b2, nb) ||
         segment_triangle_intersect(a1, a2, b0, b1, b2, nb) ||
         segment_triangle_intersect(a2, a0, b0, b1, b2, nb) ||
         segment_triangle_intersect(b0, b1, a0, a1, a2, na) ||
         segment_triangle_intersect(b1, b2, a0, a1, a2, na) ||
         segment_triangle_intersect(b2, b0, a0, a1, a2, na);
}

std::vector<std::pair<int, int>> intersecting_face_pairs(const MatrixX3d& V, const MatrixX3i& F,
                                                         const IntersectionOptions& options) {
  if (!options.between_components_only) return find_pairs(V, F, nullptr, false);
  MQ_CHECK(F.rows() == 0 || (F.minCoeff() >= 0 && F.maxCoeff() < V.rows()), InvalidInput,
           "intersection test: face index out of range [0, ", V.rows(), ")");
  std::vector<int> component;
  connected_components(F, static_cast<int>(V.rows()), component);
  return find_pairs(V, F, &component, false);
}

std::vector<std::pair<int, int>> intersecting_face_pairs_between(const MatrixX3d& V,
                                                                 const MatrixX3i& F,
                                                                 const std::vector<int>& label) {
  MQ_CHECK(static_cast<Eigen::Index>(label.size()) == F.rows(), InvalidInput,
           "intersection test: ", label.size(), " labels for ", F.rows(), " faces");
  return find_pairs(V, F, &label, false);
}

std::vector<std::pair<int, int>> intersecting_face_pairs_touching(const MatrixX3d& V,
                                                                  const MatrixX3i& F,
                                                                  const std::vector<char>& active) {
  MQ_CHECK(static_cast<Eigen::Index>(active.size()) == F.rows(), InvalidInput,
           "intersection test: ", active.size(), " active flags for ", F.rows(), " faces");
  return find_pairs(V, F, nullptr, false, false, &active);
}

std::vector<std::pair<int, int>> intersecting_face_pairs_touching(const MatrixX3d& V,
                                                                  const MatrixX3i& F,
                                                                  const std::vector<char>& active,
                                                                  const std::vector<int>& label,
                                                                  bool same_label) {
  MQ_CHECK(static_cast<Eigen::Index>(active.size()) == F.rows() &&
               static_cast<Eigen::Index>(label.size()) == F.rows(),
           InvalidInput, "intersection test: ", active.size(), " active flags and ", label.size(),
           " labels for ", F.rows(), " faces");
  return find_pairs(V, F, &label, false, same_label, &active);
}

namespace {

// The intersecting pairs of faces of one component (component: receives each face's).
std::vector<std::pair<int, int>> pairs_within_components(const MatrixX3d& V, const MatrixX3i& F,
                                                         bool stop_at_first,
                                                         std::vector<int>& component) {
  MQ_CHECK(F.rows() == 0 || (F.minCoeff() >= 0 && F.maxCoeff() < V.rows()), InvalidInput,
           "intersection test: face index out of range [0, ", V.rows(), ")");
  // One component (an element tested on its own, as the fold repair does): every pair is within
  // it, without comparing labels.
  const bool one = connected_components(F, static_cast<int>(V.rows()), component) == 1;
  return find_pairs(V, F, one ? nullptr : &component, stop_at_first, !one);
}

}  // namespace

std::vector<int> self_intersecting_components(const MatrixX3d& V, const MatrixX3i& F) {
  std::vector<int> component;
  std::vector<int> result;
  for (const auto& [f, g] : pairs_within_components(V, F, false, component))
    result.push_back(component[f]);
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

bool self_intersects(const MatrixX3d& V, const MatrixX3i& F, std::pair<int, int>* witness) {
  MQ_CHECK(F.rows() == 0 || (F.minCoeff() >= 0 && F.maxCoeff() < V.rows()), InvalidInput,
           "intersection test: face index out of range [0, ", V.rows(), ")");
  if (witness) {
    const auto [f, g] = *witness;
    if (0 <= f && f < g && g < F.rows() && faces_intersect(V, F, f, g)) return true;
  }
  std::vector<int> component;
  const std::vector<std::pair<int, int>> pairs = pairs_within_components(V, F, true, component);
  if (pairs.empty()) return false;
  if (witness) *witness = pairs.front();
  return true;
}

bool meshes_intersect(const TriMesh& A, const TriMesh& B) {
  MQ_CHECK(A.F.rows() == 0 || (A.F.minCoeff() >= 0 && A.F.maxCoeff() < A.V.rows()), InvalidInput,
           "intersection test: face index out of range [0, ", A.V.rows(), ")");
  MQ_CHECK(B.F.rows() == 0 || (B.F.minCoeff() >= 0 && B.F.maxCoeff() < B.V.rows()), InvalidInput,
           "intersection test: face index out of range [0, ", B.V.rows(), ")");
  MQ_CHECK(A.V.allFinite() && B.V.allFinite(), InvalidInput,
           "intersection test: vertex positions are not finite");
  if (A.F.rows() == 0 || B.F.rows() == 0) return false;
  // Only faces whose boxes meet the other mesh's box can take part in an intersection; for two
  // long elements crossing once that is a small part of each.
  const auto face_box = [](const TriMesh& M, int f, Vector3d& lo, Vector3d& hi) {
    lo = M.V.row(M.F(f, 0)).cwiseMin(M.V.row(M.F(f, 1))).cwiseMin(M.V.row(M.F(f, 2))).transpose();
    hi = M.V.row(M.F(f, 0)).cwiseMax(M.V.row(M.F(f, 1))).cwiseMax(M.V.row(M.F(f, 2))).transpose();
  };
  const auto faces_meeting = [&](const TriMesh& M, const Vector3d& lo, const Vector3d& hi) {
    std::vector<int> faces;
    for (int f = 0; f < M.F.rows(); ++f) {
      Vector3d flo, fhi;
      face_box(M, f, flo, fhi);
      if ((flo.array() <= hi.array()).all() && (lo.array() <= fhi.array()).all())
        faces.push_back(f);
    }
    return faces;
  };
  const BoundingBox box_a = bounding_box(A.V, A.F), box_b = bounding_box(B.V, B.F);
  const std::vector<int> fa = faces_meeting(A, box_b.min, box_b.max);
  if (fa.empty()) return false;
  const std::vector<int> fb = faces_meeting(B, box_a.min, box_a.max);
  if (fb.empty()) return false;
  TriMesh both = extract_faces(A, fa);
  const int num_a = static_cast<int>(both.F.rows());
  append_mesh(both, extract_faces(B, fb));
  std::vector<int> label(both.F.rows(), 1);
  std::fill(label.begin(), label.begin() + num_a, 0);
  return !find_pairs(both.V, both.F, &label, true).empty();
}

}  // namespace mq
