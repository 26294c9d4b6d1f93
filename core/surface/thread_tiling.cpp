#include "core/surface/thread_tiling.h"

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <tuple>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/mesh/element_detail.h"

namespace mq {

namespace {

// Points in a hash grid of cell `cell`, for "the point nearest p within tol" (tol <= cell).
class EndGrid {
 public:
  EndGrid(const MatrixX3d& V, double cell) : V_(V), cell_(cell) {
    for (Eigen::Index i = 0; i < V.rows(); ++i)
      cells_[key(cell_of(V.row(i).transpose()))].push_back(static_cast<int>(i));
  }
  // The points in p's cell and the 26 around it (every point within a cell of p).
  std::vector<int> near(const Vector3d& p) const {
    const std::array<long long, 3> c = cell_of(p);
    std::vector<int> out;
    for (long long x = c[0] - 1; x <= c[0] + 1; ++x)
      for (long long y = c[1] - 1; y <= c[1] + 1; ++y)
        for (long long z = c[2] - 1; z <= c[2] + 1; ++z) {
          const auto it = cells_.find(key({x, y, z}));
          if (it != cells_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
        }
    return out;
  }
  // The nearest point within tol of p, ties to the lower index; -1 when none.
  int nearest(const Vector3d& p, double tol) const {
    const std::array<long long, 3> c = cell_of(p);
    int best = -1;
    double best_d = tol;
    for (long long x = c[0] - 1; x <= c[0] + 1; ++x)
      for (long long y = c[1] - 1; y <= c[1] + 1; ++y)
        for (long long z = c[2] - 1; z <= c[2] + 1; ++z) {
          const auto it = cells_.find(key({x, y, z}));
          if (it == cells_.end()) continue;
          for (const int i : it->second) {
            const double d = (V_.row(i).transpose() - p).norm();
            if (d < best_d || (d == best_d && best >= 0 && i < best)) {
              best_d = d;
              best = i;
            }
          }
        }
    return best;
  }

 private:
  std::array<long long, 3> cell_of(const Vector3d& p) const {
    return {static_cast<long long>(std::floor(p.x() / cell_)),
            static_cast<long long>(std::floor(p.y() / cell_)),
            static_cast<long long>(std::floor(p.z() / cell_))};
  }
  static unsigned long long key(const std::array<long long, 3>& c) {
    return static_cast<unsigned long long>(c[0]) * 73856093ULL ^
           static_cast<unsigned long long>(c[1]) * 19349663ULL ^
           static_cast<unsigned long long>(c[2]) * 83492791ULL;
  }
  MatrixX3d V_;  // a copy: grids outlive the vectors of pieces they were made from
  double cell_;
  std::unordered_map<unsigned long long, std::vector<int>> cells_;
};

// The footprint's principal axis d (sign: +x, else +y) and the extents along and across it.
struct FootprintAxis {
  Vector2d d = Vector2d::UnitX();
  double along = 0, across = 0;
};

FootprintAxis footprint_axis(const MatrixX3d& V) {
  FootprintAxis out;
  if (V.rows() < 2) return out;
  const Vector2d mean = V.leftCols<2>().colwise().mean().transpose();
  Eigen::Matrix2d C = Eigen::Matrix2d::Zero();
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Vector2d q = V.row(i).head<2>().transpose() - mean;
    C += q * q.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(C);
  Vector2d d = eig.eigenvectors().col(1).normalized();
  if (d.x() < -1e-12 || (std::abs(d.x()) <= 1e-12 && d.y() < 0)) d = -d;
  out.d = d;
  const Vector2d n(-d.y(), d.x());
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, clo = lo, chi = -lo;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Vector2d q = V.row(i).head<2>().transpose();
    lo = std::min(lo, q.dot(d));
    hi = std::max(hi, q.dot(d));
    clo = std::min(clo, q.dot(n));
    chi = std::max(chi, q.dot(n));
  }
  out.along = hi - lo;
  out.across = chi - clo;
  return out;
}

bool is_long(const Element& e, const Vector2d& size) {
  const FootprintAxis a = footprint_axis(e.V);
  return a.along >= 4 * a.across && ((e.hi - e.lo).array() > 0.6 * size.array()).any();
}

// A loop in the order of its boundary half-edges: the start loop as it is, the end loop (which
// runs the other way round) reversed, so that loop i of one piece meets loop j of another
// vertex for vertex in opposite orders.
std::vector<int> half_edge_order(const ThreadPiece& p, int loop) {
  if (loop == 0) return p.start;
  std::vector<int> r(p.end.size());
  for (size_t i = 0; i < r.size(); ++i) r[i] = p.end[(r.size() - i) % r.size()];
  return r;
}

// The shortest lattice vector along a thread (its footprint's axis) that maps every vertex
// with room for it onto another, and the vertices' positions t along it, lo to hi.
struct ThreadPeriod {
  Vector2d period = Vector2d::Zero();
  std::vector<double> t;  // #V(e), along period
  double lo = 0, hi = 0;
};

bool find_thread_period(const MatrixX3d& V, const FootprintAxis& axis, double margin,
                        const Eigen::Matrix2d& basis, double tol, ThreadPeriod& out) {
  // Lattice vectors along the thread, shortest first.
  const Vector2d a = basis.col(0), b = basis.col(1);
  const double row = std::abs(basis.determinant()) / std::max(a.norm(), b.norm());
  const int K = std::min(64, static_cast<int>(std::ceil(axis.along / row)) + 1);
  std::vector<std::pair<double, Vector2d>> candidates;
  for (int j = -K; j <= K; ++j)
    for (int i = -K; i <= K; ++i) {
      const Vector2d L = basis * Vector2d(i, j);
      const double len = L.norm();
      if (!(len > tol) || L.dot(axis.d) <= 0 || len > axis.along - 2 * margin) continue;
      if (std::abs(L.x() * axis.d.y() - L.y() * axis.d.x()) > 0.02 * len) continue;
      candidates.emplace_back(len, L);
    }
  std::sort(candidates.begin(), candidates.end(), [](const auto& p, const auto& q) {
    if (p.first != q.first) return p.first < q.first;
    return std::make_pair(p.second.x(), p.second.y()) < std::make_pair(q.second.x(), q.second.y());
  });
  const EndGrid grid(V, std::max(tol, 1e-300));
  std::vector<double>& t = out.t;
  t.assign(static_cast<size_t>(V.rows()), 0.0);
  for (const auto& [len, L] : candidates) {
    const Vector2d d = L / len;
    double& lo = out.lo;
    double& hi = out.hi;
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
      t[v] = V.row(v).head<2>().dot(d.transpose());
      lo = std::min(lo, t[v]);
      hi = std::max(hi, t[v]);
    }
    // Room for a whole period between the ends, and every vertex there a period from another.
    if (hi - lo - 2 * margin < len) continue;
    int tested = 0;
    bool periodic = true;
    for (Eigen::Index v = 0; v < V.rows() && periodic; ++v) {
      if (t[v] < lo + margin || t[v] > hi - margin - len) continue;
      ++tested;
      const Vector3d q = V.row(v).transpose() + Vector3d(L.x(), L.y(), 0);
      periodic = grid.nearest(q, tol) >= 0;
    }
    if (periodic && tested > 0) {
      out.period = L;
      return true;
    }
  }
  return false;
}

// The faces of F whose centroids (tf, along the period) lie strictly between c0 and c1, in
// their own vertex numbering: global[l] is the element vertex of piece vertex l.
void faces_between(const MatrixX3i& F, const std::vector<double>& tf, double c0, double c1,
                   Eigen::Index num_vertices, std::vector<Eigen::Vector3i>& faces,
                   std::vector<int>& global) {
  std::vector<int> local(static_cast<size_t>(num_vertices), -1);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (!(tf[f] > c0 && tf[f] < c1)) continue;
    Eigen::Vector3i g;
    for (int k = 0; k < 3; ++k) {
      int& l = local[static_cast<size_t>(F(f, k))];
      if (l < 0) {
        l = static_cast<int>(global.size());
        global.push_back(F(f, k));
      }
      g(k) = l;
    }
    faces.push_back(g);
  }
}

// The boundary of faces (over nv vertices) as simple closed loops, each in the order of its
// half-edges (next[v]: the boundary half-edge from v). False when a vertex has two boundary
// edges leaving it or a chain does not close.
bool simple_boundary_loops(const std::vector<Eigen::Vector3i>& faces, int nv,
                           std::vector<int>& next, std::vector<std::vector<int>>& loops) {
  // Boundary half-edges (an edge used once), as the faces run.
  std::unordered_map<long long, int> uses;
  const auto edge_key = [nv](int p, int q) {
    return static_cast<long long>(std::min(p, q)) * nv + std::max(p, q);
  };
  for (const Eigen::Vector3i& g : faces)
    for (int k = 0; k < 3; ++k) ++uses[edge_key(g(k), g((k + 1) % 3))];
  next.assign(static_cast<size_t>(nv), -1);
  for (const Eigen::Vector3i& g : faces)
    for (int k = 0; k < 3; ++k) {
      const int p = g(k), q = g((k + 1) % 3);
      if (uses[edge_key(p, q)] != 1) continue;
      if (next[p] >= 0) return false;  // two boundary edges leave p: no simple loop
      next[p] = q;
    }
  std::vector<char> seen(static_cast<size_t>(nv), 0);
  for (int v = 0; v < nv; ++v) {
    if (next[v] < 0 || seen[v]) continue;
    std::vector<int> loop;
    int w = v;
    while (w >= 0 && !seen[w]) {
      seen[w] = 1;
      loop.push_back(w);
      w = next[w];
    }
    if (w != v) return false;  // open chain
    loops.push_back(std::move(loop));
  }
  return true;
}

// end[i]: the vertex of end_loop one period from start[i] (positions V of the element, piece
// vertices mapped to it by global), each taken once; the end loop must run the other way round
// (end[i + 1] -> end[i] its boundary edges). False when it does not pair so.
bool pair_end_loop(const MatrixX3d& V, const std::vector<int>& global,
                   const std::vector<int>& start, const std::vector<int>& end_loop,
                   const std::vector<int>& next, const Vector2d& period, double tol,
                   std::vector<int>& end) {
  const size_t n = start.size();
  end.assign(n, -1);
  std::vector<char> taken(global.size(), 0);
  for (size_t i = 0; i < n; ++i) {
    const Vector3d q = V.row(global[start[i]]).transpose() + Vector3d(period.x(), period.y(), 0);
    for (const int w : end_loop)
      if ((V.row(global[w]).transpose() - q).norm() <= tol) {
        if (end[i] >= 0 || taken[w]) return false;
        end[i] = w;
      }
    if (end[i] < 0) return false;
    taken[end[i]] = 1;
  }
  for (size_t i = 0; i < n; ++i)
    if (next[end[(i + 1) % n]] != end[i]) return false;
  return true;
}

// The piece cut at c0: the faces whose centroids lie between c0 and c0 + one period, when their
// boundary is two simple loops a period apart vertex for vertex.
bool cut_at(const Element& e, int index, const ThreadPeriod& p, const std::vector<double>& tf,
            double c0, double tol, ThreadPiece& out) {
  const MatrixX3d& V = e.V;
  const std::vector<double>& t = p.t;
  const double len = p.period.norm();
  std::vector<int> global;
  std::vector<Eigen::Vector3i> faces;
  faces_between(e.F, tf, c0, c0 + len, V.rows(), faces, global);
  const int nv = static_cast<int>(global.size());
  if (faces.empty()) return false;
  std::vector<int> next;
  std::vector<std::vector<int>> loops;
  if (!simple_boundary_loops(faces, nv, next, loops)) return false;
  if (loops.size() != 2 || loops[0].size() != loops[1].size() || loops[0].size() < 3) return false;
  const auto mean_t = [&](const std::vector<int>& loop) {
    double m = 0;
    for (const int v : loop) m += t[global[v]];
    return m / static_cast<double>(loop.size());
  };
  const int s = mean_t(loops[0]) < mean_t(loops[1]) ? 0 : 1;
  std::vector<int> start = loops[static_cast<size_t>(s)];
  std::rotate(start.begin(), std::min_element(start.begin(), start.end()), start.end());
  std::vector<int> end;
  if (!pair_end_loop(V, global, start, loops[static_cast<size_t>(1 - s)], next, p.period, tol, end))
    return false;
  const size_t n = start.size();
  out = ThreadPiece();
  out.V.resize(nv + 2, 3);
  for (int v = 0; v < nv; ++v) out.V.row(v) = V.row(global[v]);
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) out.F.row(static_cast<Eigen::Index>(f)) = faces[f];
  Vector3d cs = Vector3d::Zero(), ce = Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    cs += out.V.row(start[i]).transpose();
    ce += out.V.row(end[i]).transpose();
  }
  out.start_centre = nv;
  out.end_centre = nv + 1;
  out.V.row(nv) = (cs / static_cast<double>(n)).transpose();
  out.V.row(nv + 1) = (ce / static_cast<double>(n)).transpose();
  out.start = std::move(start);
  out.end = std::move(end);
  out.kind = e.kind;
  out.period = p.period;
  out.centre = out.V.topRows(nv).leftCols<2>().colwise().mean().transpose();
  out.source = index;
  return true;
}

// Whether a face of F (positions t along the period) straddles the plane at c.
bool straddled(const MatrixX3i& F, const std::vector<double>& t, double c, double tol) {
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    double fmin = std::numeric_limits<double>::infinity(), fmax = -fmin;
    for (int k = 0; k < 3; ++k) {
      fmin = std::min(fmin, t[F(f, k)]);
      fmax = std::max(fmax, t[F(f, k)]);
    }
    if (fmin < c - tol && fmax > c + tol) return true;
  }
  return false;
}

// Candidate cuts: planes through a loop of vertices, here and a period on (a swept tube's ring
// where the tube runs level; a sloping ring leans off such a plane): the vertices' distinct
// positions with room for a period after them.
std::vector<double> cut_levels(const ThreadPeriod& p, double margin, double tol) {
  const double len = p.period.norm();
  std::vector<double> levels;
  for (const double tv : p.t)
    if (tv >= p.lo + margin && tv <= p.hi - margin - len) levels.push_back(tv);
  std::sort(levels.begin(), levels.end());
  std::vector<double> cuts;
  for (const double c : levels)
    if (cuts.empty() || c > cuts.back() + tol) cuts.push_back(c);
  return cuts;
}

// Whether the half turn maps the piece onto a lattice copy of itself. Where the layout's
// transition across a cut is a half turn, only then do the pieces on its two sides meet end to
// end (a plain weave: at its crossings, not between them).
bool half_turn_consistent(const ThreadPiece& p, const SwatchSymmetry& symmetry,
                          const Eigen::Matrix2d& basis, double tol) {
  if (!symmetry.half_turn) return true;
  const Eigen::Index nv = p.V.rows() - 2;
  const MatrixX3d tube = p.V.topRows(nv);
  const EndGrid grid(tube, std::max(tol, 1e-300));
  const auto image = [&](Eigen::Index v) {
    return Vector3d(symmetry.c.x() - p.V(v, 0), symmetry.c.y() - p.V(v, 1), p.V(v, 2));
  };
  const Eigen::Matrix2d inv = basis.inverse();
  for (Eigen::Index w = 0; w < nv; ++w) {
    const Vector3d shift = image(0) - tube.row(w).transpose();
    const Vector2d k = inv * shift.head<2>();
    const Vector2d L = basis * Vector2d(std::round(k.x()), std::round(k.y()));
    if ((L - shift.head<2>()).norm() > tol || std::abs(shift.z()) > tol) continue;
    bool all = true;
    for (Eigen::Index v = 0; v < nv && all; ++v)
      all = grid.nearest(image(v) - Vector3d(L.x(), L.y(), 0), tol) >= 0;
    if (all) return true;
  }
  return false;
}

// The squared distance from p to the nearest vertex of the swatch's other elements.
double clearance_to_others(const PreparedSwatch& swatch, int index, const Vector3d& p) {
  double clearance = std::numeric_limits<double>::infinity();
  for (size_t o = 0; o < swatch.elements.size(); ++o) {
    if (static_cast<int>(o) == index) continue;
    const MatrixX3d& W = swatch.elements[o].V;
    for (Eigen::Index w = 0; w < W.rows(); ++w)
      clearance = std::min(clearance, (W.row(w).transpose() - p).squaredNorm());
  }
  return clearance;
}

// Cuts one period of thread element e, between planes orthogonal to the lattice vector along
// it. False when e is not such a thread (see thread_tiling).
bool cut_piece(const PreparedSwatch& swatch, int index, const SwatchSymmetry& symmetry,
               const Eigen::Matrix2d& basis, double tol, ThreadPiece& out) {
  const Element& e = swatch.elements[static_cast<size_t>(index)];
  const MatrixX3i& F = e.F;
  const FootprintAxis axis = footprint_axis(e.V);
  const double margin = std::max(axis.across, tol);
  ThreadPeriod p;
  if (!find_thread_period(e.V, axis, margin, basis, tol, p)) return false;
  const double len = p.period.norm();
  std::vector<double> tf(static_cast<size_t>(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    tf[f] = (p.t[F(f, 0)] + p.t[F(f, 1)] + p.t[F(f, 2)]) / 3;
  // Of the clean cuts, one consistent with the half turn if any is, and of those the one whose
  // loop's centre keeps farthest from the other elements: an end left there is capped where no
  // crossing thread presses on the cap (its centre, not its vertices: a coarse tube's vertices
  // miss the point where another passes closest).
  double best_clearance = -1;
  bool best_consistent = false;
  for (const double c : cut_levels(p, margin, tol)) {
    if (straddled(F, p.t, c, tol) || straddled(F, p.t, c + len, tol)) continue;
    ThreadPiece piece;
    if (!cut_at(e, index, p, tf, c, tol, piece)) continue;
    const bool consistent = half_turn_consistent(piece, symmetry, basis, tol);
    if (best_consistent && !consistent) continue;
    const double clearance =
        clearance_to_others(swatch, index, piece.V.row(piece.start_centre).transpose());
    if ((consistent && !best_consistent) || clearance > best_clearance * (1 + 1e-9) + 1e-300) {
      best_clearance = clearance;
      best_consistent = consistent;
      out = std::move(piece);
    }
  }
  return best_clearance >= 0;
}

}  // namespace

bool long_elements(const PreparedSwatch& swatch) {
  const size_t n = swatch.elements.size();
  if (n < 2) return false;
  size_t count = 0;
  for (const Element& e : swatch.elements) count += is_long(e, swatch.size.head<2>()) ? 1 : 0;
  return 2 * count > n;
}

ThreadTiling thread_tiling(const PreparedSwatch& swatch, const SwatchSymmetry& symmetry) {
  ThreadTiling none;
  if (!symmetry.periodic || swatch.elements.empty()) return none;
  Eigen::Matrix2d basis;
  basis.col(0) = symmetry.a;
  basis.col(1) = symmetry.b;
  if (!(std::abs(basis.determinant()) > 0)) return none;
  const Eigen::Matrix2d inv = basis.inverse();
  // Exact copies coincide to rounding; a file's rounding is far below an edge.
  const double tol =
      1e-3 * (swatch.mean_edge_length > 0 ? swatch.mean_edge_length : swatch.size.norm());
  // Threads nearest the swatch's middle first: their pieces lie among crossing threads.
  const Vector2d middle = 0.5 * swatch.size.head<2>();
  std::vector<int> order(swatch.elements.size());
  std::vector<double> distance(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    order[i] = static_cast<int>(i);
    distance[i] = (element_centre(swatch.elements[i]) - middle).norm();
  }
  std::sort(order.begin(), order.end(), [&](int p, int q) {
    return distance[p] != distance[q] ? distance[p] < distance[q] : p < q;
  });
  ThreadTiling out;
  std::vector<EndGrid> grids;
  grids.reserve(swatch.elements.size());
  for (const int i : order) {
    const Element& e = swatch.elements[static_cast<size_t>(i)];
    if (!is_long(e, swatch.size.head<2>())) return none;
    // Already a lattice copy of a piece: its vertex nearest its centre is a copy of a piece's.
    const Vector2d c = element_centre(e);
    Eigen::Index q = 0;
    for (Eigen::Index v = 1; v < e.V.rows(); ++v)
      if ((e.V.row(v).head<2>().transpose() - c).squaredNorm() <
          (e.V.row(q).head<2>().transpose() - c).squaredNorm())
        q = v;
    const Vector3d p = e.V.row(q).transpose();
    bool covered = false;
    for (size_t r = 0; r < out.pieces.size() && !covered; ++r) {
      const ThreadPiece& piece = out.pieces[r];
      double reach = 0;
      for (Eigen::Index v = 0; v < piece.V.rows(); ++v)
        reach = std::max(reach, (piece.V.row(v).head<2>().transpose() - piece.centre).norm());
      const Vector2d k = inv * (p.head<2>() - piece.centre);
      const int span = static_cast<int>(std::ceil(reach * inv.norm())) + 1;
      for (int j = static_cast<int>(std::floor(k.y())) - span;
           j <= static_cast<int>(std::ceil(k.y())) + span && !covered; ++j)
        for (int ii = static_cast<int>(std::floor(k.x())) - span;
             ii <= static_cast<int>(std::ceil(k.x())) + span && !covered; ++ii) {
          const Vector2d L = basis * Vector2d(ii, j);
          covered = grids[r].nearest(p - Vector3d(L.x(), L.y(), 0), tol) >= 0;
        }
    }
    if (covered) continue;
    ThreadPiece piece;
    if (!cut_piece(swatch, i, symmetry, basis, tol, piece)) return none;
    out.pieces.push_back(std::move(piece));
    grids.emplace_back(out.pieces.back().V, std::max(tol, 1e-300));
  }
  return out;
}

namespace {

// A piece's loop as placed: its vertices' positions in half-edge order, centre and shortest
// edge (infinite when it has none).
struct PlacedLoop {
  std::vector<Vector3d> p;
  Vector3d centre = Vector3d::Zero();
  double edge = 0;
};

// Loop 2k + l is placed piece k's loop l.
std::vector<PlacedLoop> placed_loops(const std::vector<PlacedPiece>& placed,
                                     const ThreadTiling& tiling,
                                     const std::function<Vector3d(int, int)>& position) {
  const int n = static_cast<int>(placed.size());
  std::vector<PlacedLoop> loops(static_cast<size_t>(2 * n));
  tbb::parallel_for(0, 2 * n, [&](int i) {
    const PlacedPiece& pp = placed[static_cast<size_t>(i / 2)];
    const std::vector<int> ring = half_edge_order(tiling.pieces[pp.piece], i % 2);
    PlacedLoop& l = loops[static_cast<size_t>(i)];
    for (const int v : ring) l.p.push_back(position(i / 2, v));
    for (const Vector3d& q : l.p) l.centre += q;
    l.centre /= static_cast<double>(std::max<size_t>(1, l.p.size()));
    l.edge = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < l.p.size(); ++k)
      l.edge = std::min(l.edge, (l.p[(k + 1) % l.p.size()] - l.p[k]).norm());
  });
  return loops;
}

// Whether loop B (as many vertices as A) meets A vertex for vertex within tol, in opposite
// orders: A's vertex k nearest B's vertex (offset - k) mod m for one offset; the largest
// distance in gap.
bool loops_meet(const PlacedLoop& A, const PlacedLoop& B, double tol, int& offset, double& gap) {
  const size_t m = A.p.size();
  offset = -1;
  gap = 0;
  bool ok = true;
  for (size_t k = 0; k < m && ok; ++k) {
    size_t best = 0;
    double bd = std::numeric_limits<double>::infinity();
    for (size_t q = 0; q < m; ++q) {
      const double d = (B.p[q] - A.p[k]).norm();
      if (d < bd) {
        bd = d;
        best = q;
      }
    }
    const int o = static_cast<int>((best + k) % m);
    ok = bd <= tol && (offset < 0 || o == offset);
    offset = o;
    gap = std::max(gap, bd);
  }
  return ok;
}

// Each loop in at most one weld, the closest first (ties by loops), then in loop order.
std::vector<ThreadWeld> closest_welds(std::vector<ThreadWeld> all, int loops) {
  std::sort(all.begin(), all.end(), [](const ThreadWeld& p, const ThreadWeld& q) {
    if (p.gap != q.gap) return p.gap < q.gap;
    return std::make_tuple(p.a, p.loop_a, p.b, p.loop_b) <
           std::make_tuple(q.a, q.loop_a, q.b, q.loop_b);
  });
  std::vector<char> used(static_cast<size_t>(loops), 0);
  std::vector<ThreadWeld> out;
  for (const ThreadWeld& w : all) {
    const size_t la = static_cast<size_t>(2 * w.a + w.loop_a),
                 lb = static_cast<size_t>(2 * w.b + w.loop_b);
    if (used[la] || used[lb]) continue;
    used[la] = used[lb] = 1;
    out.push_back(w);
  }
  std::sort(out.begin(), out.end(), [](const ThreadWeld& p, const ThreadWeld& q) {
    return std::make_tuple(p.a, p.loop_a, p.b, p.loop_b) <
           std::make_tuple(q.a, q.loop_a, q.b, q.loop_b);
  });
  return out;
}

}  // namespace

std::vector<ThreadWeld> find_thread_welds(const std::vector<PlacedPiece>& placed,
                                          const ThreadTiling& tiling,
                                          const std::function<Vector3d(int, int)>& position,
                                          double tolerance) {
  const int n = static_cast<int>(placed.size());
  const std::vector<PlacedLoop> loops = placed_loops(placed, tiling, position);
  double cell = 0;
  for (const PlacedLoop& l : loops)
    if (std::isfinite(l.edge)) cell = std::max(cell, tolerance * l.edge);
  if (!(cell > 0)) return {};
  // Candidates: loops whose centres lie within the tolerance, tested vertex for vertex.
  MatrixX3d centres(2 * n, 3);
  for (int i = 0; i < 2 * n; ++i) centres.row(i) = loops[static_cast<size_t>(i)].centre.transpose();
  const EndGrid grid(centres, cell);
  std::vector<std::vector<ThreadWeld>> found(static_cast<size_t>(2 * n));
  tbb::parallel_for(0, 2 * n, [&](int i) {
    const PlacedLoop& A = loops[static_cast<size_t>(i)];
    const size_t m = A.p.size();
    if (m < 3 || !std::isfinite(A.edge)) return;
    for (const int j : grid.near(A.centre)) {
      if (j <= i || j / 2 == i / 2) continue;
      const PlacedLoop& B = loops[static_cast<size_t>(j)];
      if (B.p.size() != m) continue;
      const double tol = tolerance * std::min(A.edge, B.edge);
      if ((A.centre - B.centre).norm() > tol) continue;
      int offset = -1;
      double gap = 0;
      if (loops_meet(A, B, tol, offset, gap))
        found[static_cast<size_t>(i)].push_back({i / 2, i % 2, j / 2, j % 2, offset, gap});
    }
  });
  std::vector<ThreadWeld> all;
  for (const std::vector<ThreadWeld>& f : found) all.insert(all.end(), f.begin(), f.end());
  return closest_welds(std::move(all), 2 * n);
}

namespace {

// Whether placed piece k is dropped (none is when `dropped` is empty).
bool is_dropped(const std::vector<char>& dropped, int k) {
  return !dropped.empty() && dropped[static_cast<size_t>(k)] != 0;
}

// partner[2k + l]: the weld at piece k's loop l, between pieces both kept (-1: none).
std::vector<int> weld_partners(int n, const std::vector<ThreadWeld>& welds,
                               const std::vector<char>& dropped) {
  std::vector<int> partner(static_cast<size_t>(2 * n), -1);
  for (size_t w = 0; w < welds.size(); ++w) {
    const ThreadWeld& x = welds[w];
    if (is_dropped(dropped, x.a) || is_dropped(dropped, x.b)) continue;
    partner[static_cast<size_t>(2 * x.a + x.loop_a)] = static_cast<int>(w);
    partner[static_cast<size_t>(2 * x.b + x.loop_b)] = static_cast<int>(w);
  }
  return partner;
}

// The pieces of thread `id` that starts at `first`: along its end loop's welds, then along its
// start loop's, each marked in thread_of; a chain stops where it closes on itself.
std::vector<int> thread_chain(int first, int id, const std::vector<int>& partner,
                              const std::vector<ThreadWeld>& welds, std::vector<int>& thread_of) {
  std::vector<int> chain{first};
  thread_of[first] = id;
  for (int loop = 1; loop >= 0; --loop) {
    int k = first, l = loop;
    while (true) {
      const int w = partner[static_cast<size_t>(2 * k + l)];
      if (w < 0) break;
      const ThreadWeld& x = welds[static_cast<size_t>(w)];
      const bool from_a = x.a == k && x.loop_a == l;
      const int next = from_a ? x.b : x.a, next_loop = from_a ? x.loop_b : x.loop_a;
      if (thread_of[next] >= 0) break;  // closed on itself
      thread_of[next] = id;
      chain.push_back(next);
      k = next;
      l = 1 - next_loop;
    }
  }
  return chain;
}

// One thread assembled from a chain of welded pieces: its vertices (base face, barycentric
// coordinates, height), faces and each face's piece. map[k] is the thread vertex each vertex of
// piece k became (shared across the welds).
class ThreadAssembly {
 public:
  ThreadAssembly(const std::vector<PlacedPiece>& placed, const ThreadTiling& tiling,
                 const std::vector<ThreadWeld>& welds, const std::vector<int>& partner,
                 std::vector<std::vector<int>>& map)
      : placed_(placed), tiling_(tiling), welds_(welds), partner_(partner), map_(map) {}

  // Piece k's faces; a loop welded to a piece already in the thread shares its vertices.
  void add_piece(int k) {
    const ThreadPiece& piece = piece_of(k);
    const SurfaceElement& s = placed_[k].element;
    std::vector<int>& mk = map_[static_cast<size_t>(k)];
    mk.assign(static_cast<size_t>(piece.V.rows()), -1);
    for (int l = 0; l < 2; ++l) {
      const int w = partner_[static_cast<size_t>(2 * k + l)];
      if (w < 0) continue;
      const ThreadWeld& x = welds_[static_cast<size_t>(w)];
      const bool from_a = x.a == k && x.loop_a == l;
      const int other = from_a ? x.b : x.a, other_loop = from_a ? x.loop_b : x.loop_a;
      if (map_[static_cast<size_t>(other)].empty() || (other == k && other_loop == l)) continue;
      const std::vector<int> mine = half_edge_order(piece, l);
      const std::vector<int> theirs = half_edge_order(piece_of(other), other_loop);
      const int m = static_cast<int>(mine.size());
      const std::vector<int>& mo = map_[static_cast<size_t>(other)];
      for (int i = 0; i < m; ++i) {
        const int target =
            mo[static_cast<size_t>(theirs[static_cast<size_t>(((x.offset - i) % m + m) % m)])];
        if (target >= 0) mk[static_cast<size_t>(mine[static_cast<size_t>(i)])] = target;
      }
    }
    const int tube = static_cast<int>(piece.V.rows()) - 2;
    for (int v = 0; v < tube; ++v)
      if (mk[static_cast<size_t>(v)] < 0) mk[static_cast<size_t>(v)] = add_vertex(s, v);
    for (Eigen::Index f = 0; f < piece.F.rows(); ++f) {
      F_.emplace_back(mk[piece.F(f, 0)], mk[piece.F(f, 1)], mk[piece.F(f, 2)]);
      faces_of_.push_back(k);
    }
  }

  // A thread closed on itself through one piece: its last weld joins two loops already given
  // vertices of their own; the cycle closes by merging them.
  void close_cycle(const std::vector<int>& chain) {
    for (const int k : chain)
      for (int l = 0; l < 2; ++l) {
        const int w = partner_[static_cast<size_t>(2 * k + l)];
        if (w < 0) continue;
        const ThreadWeld& x = welds_[static_cast<size_t>(w)];
        if (!(x.a == k && x.loop_a == l)) continue;
        const std::vector<int> ra = half_edge_order(piece_of(x.a), x.loop_a),
                               rb = half_edge_order(piece_of(x.b), x.loop_b);
        const int m = static_cast<int>(ra.size());
        std::vector<int> remap;
        for (int i = 0; i < m; ++i) {
          const int va =
              map_[static_cast<size_t>(x.a)][static_cast<size_t>(ra[static_cast<size_t>(i)])];
          const int vb =
              map_[static_cast<size_t>(x.b)]
                  [static_cast<size_t>(rb[static_cast<size_t>(((x.offset - i) % m + m) % m)])];
          if (va != vb) {
            if (remap.empty()) remap.resize(face_.size());
            for (size_t q = 0; q < remap.size(); ++q) remap[q] = static_cast<int>(q);
            remap[static_cast<size_t>(std::max(va, vb))] = std::min(va, vb);
            for (Eigen::Vector3i& g : F_)
              for (int c = 0; c < 3; ++c) g(c) = remap[static_cast<size_t>(g(c))];
          }
        }
      }
  }

  // Caps on the loops left open (a fan from the loop's centre); returns how many.
  int cap_open_loops(const std::vector<int>& chain) {
    int caps = 0;
    for (const int k : chain) {
      const ThreadPiece& piece = piece_of(k);
      for (int l = 0; l < 2; ++l) {
        if (partner_[static_cast<size_t>(2 * k + l)] >= 0) continue;
        const std::vector<int> ring = half_edge_order(piece, l);
        const std::vector<int>& mk = map_[static_cast<size_t>(k)];
        const int c =
            add_vertex(placed_[k].element, l == 0 ? piece.start_centre : piece.end_centre);
        const int m = static_cast<int>(ring.size());
        for (int i = 0; i < m; ++i) {
          F_.emplace_back(c, mk[static_cast<size_t>(ring[static_cast<size_t>((i + 1) % m)])],
                          mk[static_cast<size_t>(ring[static_cast<size_t>(i)])]);
          faces_of_.push_back(k);
        }
        ++caps;
      }
    }
    return caps;
  }

  // The thread as one element of `kind`; vertices no face uses any more (merged when a cycle
  // closed) are dropped.
  SurfaceElement element(int kind) const {
    std::vector<int> used(face_.size(), -1);
    int nv = 0;
    for (const Eigen::Vector3i& g : F_)
      for (int c = 0; c < 3; ++c)
        if (used[static_cast<size_t>(g(c))] < 0) used[static_cast<size_t>(g(c))] = nv++;
    SurfaceElement e;
    e.kind = kind;
    e.F.resize(static_cast<Eigen::Index>(F_.size()), 3);
    for (size_t f = 0; f < F_.size(); ++f)
      for (int c = 0; c < 3; ++c)
        e.F(static_cast<Eigen::Index>(f), c) = used[static_cast<size_t>(F_[f](c))];
    e.face.resize(static_cast<size_t>(nv));
    e.barycentric.resize(nv, 3);
    e.height.resize(nv);
    const bool sourced = source_.size() == face_.size();
    if (sourced) {
      e.source.resize(nv, 3);
      e.source_element.resize(static_cast<size_t>(nv));
    }
    for (size_t v = 0; v < face_.size(); ++v) {
      const int u = used[v];
      if (u < 0) continue;
      e.face[static_cast<size_t>(u)] = face_[v];
      e.barycentric.row(u) = bary_[v].transpose();
      e.height(u) = height_[v];
      if (sourced) {
        e.source.row(u) = source_[v].transpose();
        e.source_element[static_cast<size_t>(u)] = source_element_[v];
      }
    }
    return e;
  }

  std::vector<int>& faces_of() { return faces_of_; }

 private:
  const ThreadPiece& piece_of(int k) const {
    return tiling_.pieces[static_cast<size_t>(placed_[k].piece)];
  }
  int add_vertex(const SurfaceElement& s, int v) {
    face_.push_back(s.face[static_cast<size_t>(v)]);
    bary_.push_back(s.barycentric.row(v).transpose());
    height_.push_back(s.height(v));
    if (s.source.rows() > v) {  // the piece's sources (SurfaceElement::source), when kept
      source_.push_back(s.source.row(v).transpose());
      source_element_.push_back(s.source_element[static_cast<size_t>(v)]);
    }
    return static_cast<int>(face_.size()) - 1;
  }

  const std::vector<PlacedPiece>& placed_;
  const ThreadTiling& tiling_;
  const std::vector<ThreadWeld>& welds_;
  const std::vector<int>& partner_;
  std::vector<std::vector<int>>& map_;
  std::vector<int> faces_of_;
  std::vector<Eigen::Vector3i> F_;
  std::vector<int> face_;
  std::vector<Vector3d> bary_;
  std::vector<double> height_;
  std::vector<Vector3d> source_;
  std::vector<int> source_element_;
};

}  // namespace

std::vector<SurfaceElement> weld_threads(const std::vector<PlacedPiece>& placed,
                                         const ThreadTiling& tiling,
                                         const std::vector<ThreadWeld>& welds,
                                         const std::vector<char>& dropped, ThreadWeldStats* stats,
                                         std::vector<std::vector<int>>* face_piece,
                                         int min_pieces) {
  const int n = static_cast<int>(placed.size());
  const std::vector<int> partner = weld_partners(n, welds, dropped);
  ThreadWeldStats st;
  std::vector<SurfaceElement> out;
  if (face_piece) face_piece->clear();
  std::vector<int> thread_of(static_cast<size_t>(n), -1);
  std::vector<char> kept(static_cast<size_t>(n), 0);  // in a thread made
  // The vertex of the thread being built that each vertex of each of its pieces became.
  std::vector<std::vector<int>> map(static_cast<size_t>(n));
  for (int first = 0; first < n; ++first) {
    if (is_dropped(dropped, first) || thread_of[first] >= 0) continue;
    const int id = static_cast<int>(out.size());
    const std::vector<int> chain = thread_chain(first, id, partner, welds, thread_of);
    if (static_cast<int>(chain.size()) < min_pieces) {
      ++st.short_threads;
      continue;
    }
    for (const int k : chain) kept[static_cast<size_t>(k)] = 1;
    ThreadAssembly thread(placed, tiling, welds, partner, map);
    for (const int k : chain) thread.add_piece(k);
    thread.close_cycle(chain);
    const int caps = thread.cap_open_loops(chain);
    st.caps += caps;
    out.push_back(thread.element(tiling.pieces[static_cast<size_t>(placed[first].piece)].kind));
    if (face_piece) face_piece->push_back(std::move(thread.faces_of()));
    ++st.threads;
    st.closed_threads += caps > 0 ? 0 : 1;
    for (const int k : chain) std::vector<int>().swap(map[static_cast<size_t>(k)]);
  }
  for (const ThreadWeld& x : welds)
    st.welds +=
        is_dropped(dropped, x.a) || is_dropped(dropped, x.b) || !kept[static_cast<size_t>(x.a)] ? 0
                                                                                                : 1;
  if (stats) *stats = st;
  return out;
}

void reduce_piece_detail(ThreadTiling& tiling, const PreparedSwatch& full,
                         const PreparedSwatch& detailed) {
  tbb::parallel_for(size_t(0), tiling.pieces.size(), [&](size_t i) {
    ThreadPiece& p = tiling.pieces[i];
    const double share = static_cast<double>(detailed.elements[p.source].F.rows()) /
                         static_cast<double>(full.elements[p.source].F.rows());
    if (!(share < 1)) return;
    TriMesh tube;
    tube.V = p.V;
    tube.F = p.F;
    QuadricSimplification s = simplify_to_share(tube, share, ElementDetailOptions().min_faces);
    // The loops are on the tube's boundary, which stays; the centres (on no face) go back on.
    std::vector<int> index(static_cast<size_t>(p.V.rows()), -1);
    for (size_t v = 0; v < s.origin_vertex.size(); ++v)
      index[s.origin_vertex[v]] = static_cast<int>(v);
    MatrixX3d V = s.mesh.V;
    for (int* centre : {&p.start_centre, &p.end_centre}) {
      if (index[*centre] < 0) {
        V.conservativeResize(V.rows() + 1, 3);
        V.row(V.rows() - 1) = p.V.row(*centre);
        index[*centre] = static_cast<int>(V.rows() - 1);
      }
      *centre = index[*centre];
    }
    for (std::vector<int>* loop : {&p.start, &p.end})
      for (int& v : *loop) {
        MQ_ASSERT(index[v] >= 0);  // a cut loop is on the boundary, which stays
        v = index[v];
      }
    p.V = std::move(V);
    p.F = std::move(s.mesh.F);
  });
}

}  // namespace mq
