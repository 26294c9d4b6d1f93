#include "core/planar/swatch_symmetry.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <vector>

#include "core/mesh/mesh_intersections.h"

namespace mq {

namespace {

struct Sample {
  std::vector<Vector3d> p, n;
};

// Mean Eq. (1) cost of the sample mapped by x -> sign * x + t (xy; normals alike) against the
// swatch, over the points that land where the swatch is whole (at least a margin inside its
// footprint); infinity when fewer than min_points do.
// entries (optional, one per sample point, -1 = none): each point's face at a nearby shift,
// which starts its search (SwatchFaceTree::min_face_cost's hint: the same minimum, found
// faster), replaced by the face found here. A compass step moves t by a fraction of a cell, so
// most points keep their face.
double mean_cost(const SwatchFaceTree& faces, const Sample& s, double sign, const Vector2d& t,
                 const Vector2d& size, double margin, double lambda, size_t min_points,
                 std::vector<int>* entries = nullptr) {
  std::vector<double> costs;
  costs.reserve(s.p.size());
  for (size_t i = 0; i < s.p.size(); ++i) {
    const Vector3d q(sign * s.p[i].x() + t.x(), sign * s.p[i].y() + t.y(), s.p[i].z());
    if (q.x() < margin || q.y() < margin || q.x() > size.x() - margin || q.y() > size.y() - margin)
      continue;
    const Vector3d n(sign * s.n[i].x(), sign * s.n[i].y(), s.n[i].z());
    if (entries) {
      int& entry = (*entries)[i];
      costs.push_back(faces.min_face_cost(q, n, lambda, &entry, kInf, entry));
    } else {
      costs.push_back(faces.min_face_cost(q, n, lambda));
    }
  }
  if (costs.size() < min_points) return std::numeric_limits<double>::infinity();
  // The better half: a shifted point that lands where the sheet has run out (beyond its last
  // row of rings, still inside its box) is no evidence against the period; on a sheet two
  // rings high that is half of the points for the period along y.
  const size_t keep = std::max<size_t>(1, costs.size() / 2);
  std::nth_element(costs.begin(), costs.begin() + static_cast<std::ptrdiff_t>(keep - 1),
                   costs.end());
  double sum = 0;
  for (size_t i = 0; i < keep; ++i) sum += costs[i];
  return sum / static_cast<double>(keep);
}

// Compass search from t down to a step of `finest`. Each trial starts its points' searches at
// the faces they had at t (mean_cost's entries): the same costs, so the same path.
Vector2d refine(const SwatchFaceTree& faces, const Sample& s, double sign, Vector2d t,
                const Vector2d& size, double margin, double lambda, size_t min_points, double step,
                double finest, double& cost) {
  std::vector<int> at_t(s.p.size(), -1), trial;
  cost = mean_cost(faces, s, sign, t, size, margin, lambda, min_points, &at_t);
  while (step >= finest) {
    bool moved = false;
    const Vector2d moves[4] = {{step, 0}, {-step, 0}, {0, step}, {0, -step}};
    for (const Vector2d& m : moves) {
      trial = at_t;
      const double c = mean_cost(faces, s, sign, t + m, size, margin, lambda, min_points, &trial);
      if (c < cost * (1 - 1e-12)) {
        cost = c;
        t += m;
        at_t.swap(trial);
        moved = true;
        break;
      }
    }
    if (!moved) step *= 0.5;
  }
  return t;
}

// An evenly strided sample of up to `count` face centroids with their unit normals (faces of no
// area skipped).
Sample strided_sample(const MatrixX3d& V, const MatrixX3i& F, Eigen::Index count) {
  Sample s;
  const Eigen::Index want = std::min<Eigen::Index>(count, F.rows());
  for (Eigen::Index k = 0; k < want; ++k) {
    const Eigen::Index f = k * F.rows() / want;
    const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;
    s.p.push_back((a + b + c) / 3.0);
    s.n.push_back(n.normalized());
  }
  return s;
}

// The elements' footprint box centres.
std::vector<Vector2d> element_box_centres(const PreparedSwatch& swatch) {
  std::vector<Vector2d> c;
  for (const Element& e : swatch.elements) c.push_back(0.5 * (e.lo + e.hi));
  return c;
}

// The index of the centre nearest p (the first on a tie).
size_t nearest_centre(const std::vector<Vector2d>& c, const Vector2d& p) {
  size_t k = 0;
  for (size_t i = 1; i < c.size(); ++i)
    if ((c[i] - p).squaredNorm() < (c[k] - p).squaredNorm()) k = i;
  return k;
}

// The `count` centres nearest centre k, nearest first (ties by index), k itself among them only
// when `with_k`.
std::vector<size_t> nearest_centres(const std::vector<Vector2d>& c, size_t k, size_t count,
                                    bool with_k) {
  std::vector<size_t> order;
  for (size_t j = 0; j < c.size(); ++j)
    if (j != k || with_k) order.push_back(j);
  const size_t n = std::min(count, order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n), order.end(),
                    [&](size_t a, size_t b) {
                      const double da = (c[a] - c[k]).squaredNorm();
                      const double db = (c[b] - c[k]).squaredNorm();
                      return da < db || (da == db && a < b);
                    });
  order.resize(n);
  return order;
}

// Shifts a grid search may evaluate (each 128 nearest-face queries): beyond it the search tries
// the shifts that map one element onto another, or a coarser grid. The Table 1 swatches need
// at most a few thousand.
constexpr double kMaxGridShifts = 16384;

using ShiftMatch = std::pair<double, Vector2d>;  // (mean cost, shift)

// The maps x -> sign * x + t of the swatch onto itself (sign 1: periods, -1: half turns about
// t / 2) over a range of shifts t: matches of mean Eq. (1) cost within 1 + tolerance.
class SymmetrySearch {
 public:
  SymmetrySearch(const PreparedSwatch& swatch, const SwatchFaceTree& faces, double cell,
                 double tolerance, double margin)
      : faces_(faces),
        sample_(strided_sample(swatch.mesh.V, swatch.mesh.F, 128)),
        size_(swatch.size.head<2>()),
        margin_(margin),
        min_points_(std::max<size_t>(16, sample_.p.size() / 5)),
        lambda_(1.0 / cell),
        step_(0.5 * cell),
        cell_(cell),
        tolerance_(tolerance),
        centre_(element_box_centres(swatch)),
        middle_(centre_.empty() ? 0 : nearest_centre(centre_, 0.5 * size_)) {}

  // Whole-step shifts in both directions for the periods, shifts over [0, 2 size] for the half
  // turn (which maps [0, size] to [-size, 0] before the shift).
  std::vector<ShiftMatch> search(double sign, const Vector2d& from, const Vector2d& to) const {
    const double grid_shifts =
        std::floor((to.x() - from.x()) / step_ + 1) * std::floor((to.y() - from.y()) / step_ + 1);
    if (grid_shifts > kMaxGridShifts && centre_.size() >= 2) return element_shifts(sign, from, to);
    // One large element on a fine grid: the grid coarsened to the budget.
    const double grid_step =
        grid_shifts > kMaxGridShifts ? step_ * std::sqrt(grid_shifts / kMaxGridShifts) : step_;
    return grid_search(sign, from, to, grid_step);
  }

 private:
  double cost(double sign, const Vector2d& t, std::vector<int>* entries = nullptr) const {
    return mean_cost(faces_, sample_, sign, t, size_, margin_, lambda_, min_points_, entries);
  }
  Vector2d refined(double sign, const Vector2d& t, double step, double& c) const {
    return refine(faces_, sample_, sign, t, size_, margin_, lambda_, min_points_, step,
                  1e-7 * cell_, c);
  }

  // Many small elements (a 20 x 20 swatch of boxes: 260,000 shifts, minutes): a symmetry maps
  // the middle element onto another one, so only such shifts are tried, refined as below,
  // instead of a grid over the footprint (issue 28). The shortest periods, and half turns about
  // the nearest centres, map it onto one of its nearest elements: the 64 nearest are tried.
  std::vector<ShiftMatch> element_shifts(double sign, const Vector2d& from,
                                         const Vector2d& to) const {
    std::vector<Vector2d> tries;
    for (const size_t j : nearest_centres(centre_, middle_, 64, sign < 0)) {
      const Vector2d t = sign > 0 ? Vector2d(centre_[j] - centre_[middle_])
                                  : Vector2d(centre_[j] + centre_[middle_]);
      if ((t.array() < from.array()).any() || (t.array() > to.array()).any()) continue;
      if (sign > 0 && t.norm() < 0.5 * cell_) continue;
      tries.push_back(t);
    }
    std::vector<ShiftMatch> matches(tries.size());
    tbb::parallel_for(size_t(0), tries.size(), [&](size_t i) {
      double c = cost(sign, tries[i]);
      Vector2d t = tries[i];
      if (c < 2.0) t = refined(sign, t, 0.5 * step_, c);
      matches[i] = {c, t};
    });
    return exact(matches);
  }

  // Every shift on a grid, then its local minima under a loose bound refined.
  std::vector<ShiftMatch> grid_search(double sign, const Vector2d& from, const Vector2d& to,
                                      double grid_step) const {
    const int nx = static_cast<int>(std::floor((to.x() - from.x()) / grid_step)) + 1;
    const int ny = static_cast<int>(std::floor((to.y() - from.y()) / grid_step)) + 1;
    if (nx <= 0 || ny <= 0) return {};
    std::vector<double> costs(static_cast<size_t>(nx) * ny);
    // A row at a time, each shift's searches started at the faces of the one before it.
    tbb::parallel_for(0, ny, [&](int y) {
      std::vector<int> entries(sample_.p.size(), -1);
      for (int x = 0; x < nx; ++x) {
        const Vector2d t = from + grid_step * Vector2d(x, y);
        costs[static_cast<size_t>(y) * nx + x] = (sign > 0 && t.norm() < 0.5 * cell_)
                                                     ? std::numeric_limits<double>::infinity()
                                                     : cost(sign, t, &entries);
      }
    });
    std::vector<int> seeds;
    for (int k = 0; k < nx * ny; ++k) {
      const double c = costs[static_cast<size_t>(k)];
      if (!(c < 2.0)) continue;
      const int x = k % nx, y = k / nx;
      bool minimum = true;
      for (int dy = -1; dy <= 1 && minimum; ++dy)
        for (int dx = -1; dx <= 1 && minimum; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if ((dx || dy) && xx >= 0 && yy >= 0 && xx < nx && yy < ny &&
              costs[static_cast<size_t>(yy) * nx + xx] < c)
            minimum = false;
        }
      if (minimum) seeds.push_back(k);
    }
    std::vector<ShiftMatch> matches(seeds.size());
    tbb::parallel_for(size_t(0), seeds.size(), [&](size_t i) {
      const int k = seeds[i];
      const Vector2d t0 = from + grid_step * Vector2d(k % nx, k / nx);
      double c = 0;
      const Vector2d t = refined(sign, t0, 0.5 * grid_step, c);
      matches[i] = {c, t};
    });
    return exact(matches);
  }

  // The matches within the tolerance, in order.
  std::vector<ShiftMatch> exact(const std::vector<ShiftMatch>& matches) const {
    std::vector<ShiftMatch> found;
    for (const auto& [c, t] : matches)
      if (c <= 1 + tolerance_) found.emplace_back(c, t);
    return found;
  }

  const SwatchFaceTree& faces_;
  const Sample sample_;
  const Vector2d size_;
  const double margin_;
  const size_t min_points_;
  const double lambda_, step_, cell_, tolerance_;
  const std::vector<Vector2d> centre_;
  const size_t middle_;
};

// The lattice of the periods found: the shortest as a, the shortest not parallel to it (over
// 0.2 of a right angle's sine) as b, in the conventional signs (a along +x, b with positive y).
void lattice_from_periods(std::vector<ShiftMatch> periods, double cell, SwatchSymmetry& out) {
  // Shortest first (ties by coordinates, deterministic).
  std::sort(periods.begin(), periods.end(), [](const auto& p, const auto& q) {
    const double a = p.second.norm(), b = q.second.norm();
    if (std::abs(a - b) > 1e-9) return a < b;
    return std::make_pair(p.second.x(), p.second.y()) < std::make_pair(q.second.x(), q.second.y());
  });
  for (const auto& [c, t] : periods) {
    if (t.norm() < 0.5 * cell) continue;
    if (out.a.squaredNorm() == 0) {
      out.a = t;
      continue;
    }
    const double cross = std::abs(out.a.x() * t.y() - out.a.y() * t.x());
    if (cross > 0.2 * out.a.norm() * t.norm()) {
      out.b = t;
      out.periodic = true;
      break;
    }
  }
  if (out.periodic) {
    if (out.a.x() < 0 || (out.a.x() == 0 && out.a.y() < 0)) out.a = -out.a;
    if (out.a.x() * out.b.y() - out.a.y() * out.b.x() < 0) out.b = -out.b;
  }
}

}  // namespace

SwatchSymmetry detect_swatch_symmetry(const PreparedSwatch& swatch, const SwatchFaceTree& faces,
                                      double cell, double tolerance) {
  SwatchSymmetry out;
  const Vector2d size = swatch.size.head<2>();
  double max_element = 0;
  for (const Element& e : swatch.elements)
    max_element = std::max(max_element, e.footprint_diameter());
  const double margin = 0.1 * max_element;
  if (!(cell > 0) || size.x() <= 2 * margin || size.y() <= 2 * margin) return out;
  const SymmetrySearch search(swatch, faces, cell, tolerance, margin);
  const Vector2d reach = size - Vector2d::Constant(2 * margin);
  lattice_from_periods(search.search(1.0, -reach, reach), cell, out);
  const std::vector<ShiftMatch> turns = search.search(-1.0, Vector2d::Constant(2 * margin),
                                                      2 * size - Vector2d::Constant(2 * margin));
  if (!turns.empty()) {
    const auto best = *std::min_element(
        turns.begin(), turns.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
    out.half_turn = true;
    out.c = best.second;
  }
  return out;
}

Vector2d element_centre(const Element& e) { return e.V.leftCols<2>().colwise().mean().transpose(); }

Vector2d axis_periods(const PreparedSwatch& swatch, const SwatchFaceTree& faces, double cell,
                      double tolerance) {
  Vector2d out = Vector2d::Zero();
  const MatrixX3d& V = swatch.mesh.V;
  const MatrixX3i& F = swatch.mesh.F;
  const Vector2d size = swatch.size.head<2>();
  double max_element = 0;
  for (const Element& e : swatch.elements)
    max_element = std::max(max_element, e.footprint_diameter());
  const double margin = 0.1 * max_element;
  if (!(cell > 0)) return out;
  const Sample s = strided_sample(V, F, 64);
  const size_t min_points = std::max<size_t>(8, s.p.size() / 5);
  const double lambda = 1.0 / cell, step = 0.5 * cell;
  for (int axis = 0; axis < 2; ++axis) {
    const int n = static_cast<int>(std::floor((size(axis) - 2 * margin) / step));
    for (int k = 1; k <= n; ++k) {
      Vector2d t = Vector2d::Zero();
      t(axis) = k * step;
      const double c = mean_cost(faces, s, 1.0, t, size, margin, lambda, min_points);
      if (!(c < 2.0)) continue;
      // A one-dimensional compass along the axis.
      double best = c, h = 0.5 * step;
      while (h >= 1e-6 * cell) {
        Vector2d up = t, down = t;
        up(axis) += h;
        down(axis) -= h;
        const double cu = mean_cost(faces, s, 1.0, up, size, margin, lambda, min_points);
        const double cd = mean_cost(faces, s, 1.0, down, size, margin, lambda, min_points);
        if (cu < best && cu <= cd) {
          best = cu;
          t = up;
        } else if (cd < best) {
          best = cd;
          t = down;
        } else {
          h *= 0.5;
        }
      }
      if (best <= 1 + tolerance && t(axis) > 0.5 * cell) {
        out(axis) = t(axis);
        break;
      }
    }
  }
  return out;
}

bool repeating_elements(const PreparedSwatch& swatch) {
  const int n = static_cast<int>(swatch.elements.size());
  if (n < 4) return false;
  for (const Element& e : swatch.elements)
    if (((e.hi - e.lo).array() > 0.6 * swatch.size.head<2>().array()).any()) return false;
  const std::vector<Vector2d> c = element_box_centres(swatch);
  // The median nearest-centre distance (all pairs: swatches hold tens to hundreds of elements).
  std::vector<double> nearest(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double d = (c[i] - c[j]).norm();
      nearest[i] = std::min(nearest[i], d);
      nearest[j] = std::min(nearest[j], d);
    }
  std::nth_element(nearest.begin(), nearest.begin() + n / 2, nearest.end());
  const double tol = 0.25 * nearest[n / 2];
  if (!(tol > 0)) return false;
  // Centres in a hash grid of cell `tol`: a lookup checks the 3 x 3 cells around a point.
  std::unordered_map<long long, std::vector<int>> grid;
  auto key = [&](long long x, long long y) { return x * 1000003LL + y; };
  auto cell = [&](double v) { return static_cast<long long>(std::floor(v / tol)); };
  for (int i = 0; i < n; ++i) grid[key(cell(c[i].x()), cell(c[i].y()))].push_back(i);
  auto has_centre_near = [&](const Vector2d& p) {
    const long long cx = cell(p.x()), cy = cell(p.y());
    for (long long x = cx - 1; x <= cx + 1; ++x)
      for (long long y = cy - 1; y <= cy + 1; ++y)
        if (const auto it = grid.find(key(x, y)); it != grid.end())
          for (const int j : it->second)
            if ((c[j] - p).norm() <= tol) return true;
    return false;
  };
  // Shifts from the element nearest the footprint's centre to every other element; the shortest
  // periods are shifts to near elements: the 24 nearest are tried.
  const size_t k = nearest_centre(c, 0.5 * swatch.size.head<2>());
  const std::vector<size_t> order = nearest_centres(c, k, 24, false);
  // A shifted centre is judged only within the box of the centres (and tol): beyond it the
  // swatch ends, and an element that would lie there is missing, not out of place. The
  // footprint's box judged the shifted last row of a 3 x 3 sheet, whose rings reach past their
  // centres, as missing: 5 of 6 matched, and the sheet went to the patches (7% linked on Spot).
  Vector2d lo = c.front(), hi = c.front();
  for (const Vector2d& p : c) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  lo.array() -= tol;
  hi.array() += tol;
  for (const size_t j : order) {
    const Vector2d t = c[j] - c[k];
    int inside = 0, matched = 0;
    for (int i = 0; i < n; ++i) {
      const Vector2d p = c[i] + t;
      if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
      ++inside;
      matched += has_centre_near(p);
    }
    // Half the centres at least: a long shift keeps two or three by chance.
    if (inside >= 2 && 2 * inside >= n && matched >= 0.9 * inside) return true;
  }
  return false;
}

bool tileable(const PreparedSwatch& swatch, const SwatchSymmetry& symmetry) {
  if (!symmetry.periodic) return false;
  // The tiling of the swatch's own footprint must be as disjoint as the swatch: copies of a
  // thread one period apart overlap along their length.
  const TriMesh tiled = tile_lattice(swatch, symmetry, Vector2d::Zero(), swatch.size.head<2>());
  return !tiled.empty() && intersecting_face_pairs(tiled.V, tiled.F).empty();
}

std::vector<int> orbit_representatives(const PreparedSwatch& swatch,
                                       const SwatchSymmetry& symmetry) {
  Eigen::Matrix2d basis;
  basis.col(0) = symmetry.a;
  basis.col(1) = symmetry.b;
  const Eigen::Matrix2d inv = basis.inverse();
  const Vector2d middle = 0.5 * swatch.size.head<2>();
  // Orbits: elements whose centres differ by a lattice vector (to 1e-3 of a cell); each keeps
  // the copy nearest the swatch's centre (ties by index).
  std::vector<int> order(swatch.elements.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int p, int q) {
    const double dp = (element_centre(swatch.elements[p]) - middle).norm();
    const double dq = (element_centre(swatch.elements[q]) - middle).norm();
    if (dp != dq) return dp < dq;
    return p < q;
  });
  std::vector<int> reps;
  std::vector<Vector2d> rep_k;
  for (const int i : order) {
    const Vector2d k = inv * element_centre(swatch.elements[i]);
    bool seen = false;
    for (const Vector2d& r : rep_k) {
      const Vector2d d = k - r;
      if ((d - Vector2d(std::round(d.x()), std::round(d.y()))).cwiseAbs().maxCoeff() < 1e-3) {
        seen = true;
        break;
      }
    }
    if (seen) continue;
    reps.push_back(i);
    rep_k.push_back(k);
  }
  std::sort(reps.begin(), reps.end());
  return reps;
}

TriMesh tile_lattice(const PreparedSwatch& swatch, const SwatchSymmetry& symmetry,
                     const Vector2d& lo, const Vector2d& hi, int* orbits) {
  Eigen::Matrix2d basis;
  basis.col(0) = symmetry.a;
  basis.col(1) = symmetry.b;
  const Eigen::Matrix2d inv = basis.inverse();
  const std::vector<int> reps = orbit_representatives(swatch, symmetry);
  if (orbits) *orbits = static_cast<int>(reps.size());
  // Lattice translations whose copy of a representative meets [lo, hi].
  std::vector<const Element*> out;
  std::vector<Element> copies;
  std::vector<std::pair<int, Vector2d>> placements;
  for (const int r : reps) {
    const Element& e = swatch.elements[static_cast<size_t>(r)];
    const Vector2d c = element_centre(e);
    const double radius = 0.5 * e.footprint_diameter();
    const Vector2d corners[4] = {
        Vector2d(lo.x() - radius, lo.y() - radius), Vector2d(hi.x() + radius, lo.y() - radius),
        Vector2d(lo.x() - radius, hi.y() + radius), Vector2d(hi.x() + radius, hi.y() + radius)};
    Vector2d kmin = Vector2d::Constant(std::numeric_limits<double>::infinity()), kmax = -kmin;
    for (const Vector2d& q : corners) {
      const Vector2d k = inv * (q - c);
      kmin = kmin.cwiseMin(k);
      kmax = kmax.cwiseMax(k);
    }
    for (long j = static_cast<long>(std::floor(kmin.y()));
         j <= static_cast<long>(std::ceil(kmax.y())); ++j)
      for (long i = static_cast<long>(std::floor(kmin.x()));
           i <= static_cast<long>(std::ceil(kmax.x())); ++i) {
        const Vector2d t = basis * Vector2d(static_cast<double>(i), static_cast<double>(j));
        const Vector2d at = c + t;
        if (at.x() < lo.x() - radius || at.y() < lo.y() - radius || at.x() > hi.x() + radius ||
            at.y() > hi.y() + radius)
          continue;
        placements.emplace_back(r, t);
      }
  }
  copies.reserve(placements.size());
  for (const auto& [r, t] : placements) {
    Element e = swatch.elements[static_cast<size_t>(r)];
    e.translate(Vector3d(t.x(), t.y(), 0));
    copies.push_back(std::move(e));
  }
  out.reserve(copies.size());
  for (const Element& e : copies) out.push_back(&e);
  TriMesh tiled = merge_elements(out);
  tiled.kinds = swatch.kinds;
  return tiled;
}

}  // namespace mq
