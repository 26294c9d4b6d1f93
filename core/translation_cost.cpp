#include "core/translation_cost.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/errors.h"
#include "core/geometry_measures.h"
#include "core/point_triangle.h"

namespace mq {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Eq. (1) for one point-face pair, given the squared distance. Kept in one place (and mirrored
// in kernels/translation_cost.cl) so that every path evaluates it identically.
inline double normal_factor(const Vector3d& n, const double* fn) {
  const double dx = n(0) - fn[0], dy = n(1) - fn[1], dz = n(2) - fn[2];
  return 1.0 + std::sqrt(dx * dx + dy * dy + dz * dz);
}
inline double face_cost(double dist2, const Vector3d& n, const double* fn, double lambda) {
  return (1.0 + lambda * std::sqrt(dist2)) * normal_factor(n, fn);
}

inline double triangle_dist2(const Vector3d& q, const double* t) {
  return point_triangle_squared_distance<double>(
      q, Vector3d(t[0], t[1], t[2]), Vector3d(t[3], t[4], t[5]), Vector3d(t[6], t[7], t[8]));
}

bool all_finite(const MatrixX3d& M) { return M.allFinite(); }

void fnv1a(std::uint64_t& h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
}

// Per-offset sums of per-(offset, point) minima, in point order (deterministic).
Eigen::VectorXd sum_per_offset(const std::vector<double>& minima, Eigen::Index num_points,
                               Eigen::Index num_offsets) {
  Eigen::VectorXd E = Eigen::VectorXd::Zero(num_offsets);
  for (Eigen::Index t = 0; t < num_offsets; ++t) {
    double s = 0.0;
    for (Eigen::Index p = 0; p < num_points; ++p) s += minima[t * num_points + p];
    E(t) = s;
  }
  return E;
}

}  // namespace

void validate_translation_cost_problem(const TranslationCostProblem& problem) {
  MQ_CHECK(problem.points.rows() == problem.point_normals.rows(), InvalidInput,
           "translation cost: ", problem.points.rows(), " points but ",
           problem.point_normals.rows(), " point normals");
  MQ_CHECK(all_finite(problem.points), InvalidInput,
           "translation cost: points contain NaN or infinite values");
  MQ_CHECK(all_finite(problem.point_normals), InvalidInput,
           "translation cost: point normals contain NaN or infinite values");
  MQ_CHECK(all_finite(problem.offsets), InvalidInput,
           "translation cost: offsets contain NaN or infinite values");
  MQ_CHECK(std::isfinite(problem.lambda) && problem.lambda >= 0.0, InvalidInput,
           "translation cost: lambda must be finite and >= 0, got ", problem.lambda);
}

SwatchDistanceGrid::SwatchDistanceGrid(const MatrixX3d& V, const MatrixX3i& F, double cell_size) {
  MQ_CHECK(F.rows() > 0, InvalidInput, "swatch distance grid: the swatch has no faces");
  MQ_CHECK(V.allFinite(), InvalidInput,
           "swatch distance grid: vertices contain NaN or infinite values");
  MQ_CHECK(F.minCoeff() >= 0 && F.maxCoeff() < V.rows(), InvalidInput,
           "swatch distance grid: face index out of range [0, ", V.rows(), ")");
  MQ_CHECK(std::isfinite(cell_size) && cell_size >= 0.0, InvalidInput,
           "swatch distance grid: cell size must be finite and >= 0, got ", cell_size);
  num_faces_ = static_cast<int>(F.rows());

  std::vector<double> triangles(9 * static_cast<std::size_t>(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) triangles[9 * f + 3 * k + a] = V(F(f, k), a);
  const MatrixX3d FN = mq::face_normals(V, F);

  const BoundingBox box = bounding_box(V, F);
  const Vector3d extent = box.extent();
  const double max_cells_limit = double(1 << 26);
  auto cells_for = [&](double h) {
    double n = 1.0;
    for (int a = 0; a < 3; ++a) n *= std::max(1.0, std::ceil(extent(a) / h));
    return n;
  };
  double h = cell_size;
  if (h == 0.0) {
    h = 2.0 * mean_edge_length(V, F);
    if (!(h > 0.0)) h = std::max(extent.maxCoeff(), 1.0);
    const double max_cells = 2.0 * double(F.rows()) + 64.0;
    // Enlarging h by the cube root of the excess converges in a few steps.
    while (cells_for(h) > max_cells) h *= std::max(1.01, std::cbrt(cells_for(h) / max_cells));
  }
  MQ_CHECK(cells_for(h) <= max_cells_limit, InvalidInput, "swatch distance grid: cell size ", h,
           " would need more than 2^26 cells");
  cell_size_ = h;
  origin_ = box.min;
  for (int a = 0; a < 3; ++a) dims_(a) = static_cast<int>(std::max(1.0, std::ceil(extent(a) / h)));

  // Bin each face's bounding box into the cells it meets (CSR, two passes).
  auto face_box = [&](Eigen::Index f, Vector3d& mn, Vector3d& mx) {
    for (int a = 0; a < 3; ++a) {
      mn(a) = std::min({triangles[9 * f + a], triangles[9 * f + 3 + a], triangles[9 * f + 6 + a]});
      mx(a) = std::max({triangles[9 * f + a], triangles[9 * f + 3 + a], triangles[9 * f + 6 + a]});
    }
  };
  auto cell_range = [&](Eigen::Index f, Eigen::Vector3i& lo, Eigen::Vector3i& hi) {
    Vector3d mn, mx;
    face_box(f, mn, mx);
    for (int a = 0; a < 3; ++a) {
      lo(a) = std::clamp(static_cast<int>(std::floor((mn(a) - origin_(a)) / h)), 0, dims_(a) - 1);
      hi(a) = std::clamp(static_cast<int>(std::floor((mx(a) - origin_(a)) / h)), 0, dims_(a) - 1);
    }
  };
  const int num_cells = dims_.prod();
  std::vector<int> count(num_cells + 1, 0);
  Eigen::Vector3i lo, hi;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    cell_range(f, lo, hi);
    for (int z = lo(2); z <= hi(2); ++z)
      for (int y = lo(1); y <= hi(1); ++y)
        for (int x = lo(0); x <= hi(0); ++x) ++count[(z * dims_(1) + y) * dims_(0) + x + 1];
  }
  for (int c = 0; c < num_cells; ++c) count[c + 1] += count[c];
  cell_start_ = count;
  cell_faces_.resize(cell_start_.back());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    cell_range(f, lo, hi);
    for (int z = lo(2); z <= hi(2); ++z)
      for (int y = lo(1); y <= hi(1); ++y)
        for (int x = lo(0); x <= hi(0); ++x)
          cell_faces_[count[(z * dims_(1) + y) * dims_(0) + x]++] = static_cast<int>(f);
  }

  // Per-entry copies of the face data, in cell order.
  const std::size_t E = cell_faces_.size();
  entry_triangles_.resize(9 * E);
  entry_normals_.assign(4 * E, 0.0);
  entry_spheres_.resize(4 * E);
  for (std::size_t j = 0; j < E; ++j) {
    const int f = cell_faces_[j];
    std::copy_n(&triangles[9 * static_cast<std::size_t>(f)], 9, &entry_triangles_[9 * j]);
    for (int a = 0; a < 3; ++a) entry_normals_[4 * j + a] = FN(f, a);
    const double* t = &triangles[9 * static_cast<std::size_t>(f)];
    const Vector3d pa(t[0], t[1], t[2]), pb(t[3], t[4], t[5]), pc(t[6], t[7], t[8]);
    const Vector3d m = (pa + pb + pc) / 3.0;
    const double r = std::max({(pa - m).norm(), (pb - m).norm(), (pc - m).norm()});
    for (int a = 0; a < 3; ++a) entry_spheres_[4 * j + a] = m(a);
    // Enlarged so that rounding never lets the sphere bound exceed a true distance.
    entry_spheres_[4 * j + 3] = r * (1 + 1e-12) + 1e-12 * h;
  }

  // Per-cell box of its faces' parts and normal cone.
  cell_boxes_.assign(8 * std::size_t(num_cells), 0.0);
  cell_cones_.assign(4 * std::size_t(num_cells), 0.0);
  for (int c = 0; c < num_cells; ++c) {
    const int cx = c % dims_(0), cy = (c / dims_(0)) % dims_(1), cz = c / (dims_(0) * dims_(1));
    const Vector3d cell_lo = origin_ + h * Vector3d(cx, cy, cz);
    const Vector3d cell_hi = cell_lo + Vector3d::Constant(h);
    Vector3d bmin = Vector3d::Constant(kInf), bmax = Vector3d::Constant(-kInf);
    Vector3d mean = Vector3d::Zero();
    for (int j = cell_start_[c]; j < cell_start_[c + 1]; ++j) {
      Vector3d mn, mx;
      face_box(cell_faces_[j], mn, mx);
      // The face's box clipped to the cell (cells on the grid border keep what lies beyond,
      // since faces there are clamped in).
      for (int a = 0; a < 3; ++a) {
        const int i = a == 0 ? cx : (a == 1 ? cy : cz);
        const double clo = i == 0 ? -kInf : cell_lo(a), chi = i == dims_(a) - 1 ? kInf : cell_hi(a);
        bmin(a) = std::min(bmin(a), std::max(mn(a), clo));
        bmax(a) = std::max(bmax(a), std::min(mx(a), chi));
      }
      mean += Vector3d(&entry_normals_[4 * j]);
    }
    for (int a = 0; a < 3; ++a) {
      cell_boxes_[8 * c + a] = bmin(a);
      cell_boxes_[8 * c + 4 + a] = bmax(a);
    }
    const double len = mean.norm();
    const Vector3d dir = len > 1e-12 ? Vector3d(mean / len) : Vector3d::Zero();
    double r = 0.0;
    for (int j = cell_start_[c]; j < cell_start_[c + 1]; ++j)
      r = std::max(r, (Vector3d(&entry_normals_[4 * j]) - dir).norm());
    // Slightly enlarged so that rounding never makes the bound exceed a face's true factor.
    cell_cones_[4 * c + 0] = dir(0);
    cell_cones_[4 * c + 1] = dir(1);
    cell_cones_[4 * c + 2] = dir(2);
    cell_cones_[4 * c + 3] = r * (1 + 1e-12) + 1e-12;
  }

  std::uint64_t fp = 14695981039346656037ull;
  fnv1a(fp, origin_.data(), sizeof(double) * 3);
  fnv1a(fp, &cell_size_, sizeof(double));
  fnv1a(fp, dims_.data(), sizeof(int) * 3);
  fnv1a(fp, cell_start_.data(), sizeof(int) * cell_start_.size());
  fnv1a(fp, cell_faces_.data(), sizeof(int) * cell_faces_.size());
  fnv1a(fp, entry_triangles_.data(), sizeof(double) * entry_triangles_.size());
  fnv1a(fp, entry_normals_.data(), sizeof(double) * entry_normals_.size());
  fnv1a(fp, entry_spheres_.data(), sizeof(double) * entry_spheres_.size());
  fnv1a(fp, cell_boxes_.data(), sizeof(double) * cell_boxes_.size());
  fnv1a(fp, cell_cones_.data(), sizeof(double) * cell_cones_.size());
  fingerprint_ = fp;
}

double SwatchDistanceGrid::min_face_cost(const Vector3d& q, const Vector3d& n,
                                         double lambda) const {
  const double h = cell_size_;
  // Continuous cell coordinates of q and the (clamped) cell the rings grow from.
  double g[3];
  int c[3];
  for (int a = 0; a < 3; ++a) {
    g[a] = (q(a) - origin_(a)) / h;
    c[a] = static_cast<int>(std::clamp(std::floor(g[a]), 0.0, double(dims_(a) - 1)));
  }
  // Distance (in cells) from q to the slab of cell i along axis a.
  auto gap = [&](int a, int i) { return std::max(0.0, std::max(i - g[a], g[a] - (i + 1))); };
  // A tiny slack keeps the bounds below the true distances despite rounding.
  const double slack = 1e-9 * h;
  double best = kInf;
  for (int k = 0;; ++k) {
    if (k > 0) {
      double lb = kInf;
      for (int a = 0; a < 3; ++a)
        for (int s = -1; s <= 1; s += 2) {
          const int i = c[a] + s * k;
          if (i >= 0 && i < dims_(a)) lb = std::min(lb, gap(a, i));
        }
      if (lb == kInf) break;  // the ring lies outside the grid: every cell was visited
      if (1.0 + lambda * (lb * h - slack) >= best) break;
    }
    const int x0 = std::max(0, c[0] - k), x1 = std::min(dims_(0) - 1, c[0] + k);
    const int y0 = std::max(0, c[1] - k), y1 = std::min(dims_(1) - 1, c[1] + k);
    for (int x = x0; x <= x1; ++x) {
      for (int y = y0; y <= y1; ++y) {
        const bool shell = std::abs(x - c[0]) == k || std::abs(y - c[1]) == k;
        // Inside the ring's x/y shell every z is on the ring; otherwise only the two z caps.
        const int zs[2] = {c[2] - k, c[2] + k};
        const int z0 = shell ? std::max(0, c[2] - k) : 0;
        const int z1 = shell ? std::min(dims_(2) - 1, c[2] + k) : (k > 0 ? 1 : 0);
        for (int zi = z0; zi <= z1; ++zi) {
          const int z = shell ? zi : zs[zi];
          if (z < 0 || z >= dims_(2)) continue;
          const int cell = (z * dims_(1) + y) * dims_(0) + x;
          const int j0 = cell_start_[cell], j1 = cell_start_[cell + 1];
          if (j0 == j1) continue;
          const double* bx = &cell_boxes_[8 * cell];
          double d2 = 0.0;
          for (int a = 0; a < 3; ++a) {
            const double e = std::max(0.0, std::max(bx[a] - q(a), q(a) - bx[4 + a]));
            d2 += e * e;
          }
          const double dist_factor = 1.0 + lambda * (std::sqrt(d2) - slack);
          if (dist_factor >= best) continue;
          const double* cone = &cell_cones_[4 * cell];
          const double cx = n(0) - cone[0], cy = n(1) - cone[1], cz = n(2) - cone[2];
          const double cone_lb = std::sqrt(cx * cx + cy * cy + cz * cz) - cone[3];
          if (dist_factor * (1.0 + std::max(0.0, cone_lb)) >= best) continue;
          // Normal factor bound without a square root: skip an entry when
          // |n - n_f| >= best / df - 1 (updated whenever best improves).
          double r = best / dist_factor - 1.0;
          double r2 = r * r * (1.0 + 1e-12);
          for (int j = j0; j < j1; ++j) {
            const double* fn = &entry_normals_[4 * j];
            const double nx = n(0) - fn[0], ny = n(1) - fn[1], nz = n(2) - fn[2];
            const double dn2 = nx * nx + ny * ny + nz * nz;
            if (dn2 >= r2) continue;
            const double nf = 1.0 + std::sqrt(dn2);
            const double* sp = &entry_spheres_[4 * j];
            const double sx = q(0) - sp[0], sy = q(1) - sp[1], sz = q(2) - sp[2];
            const double sphere_lb = std::sqrt(sx * sx + sy * sy + sz * sz) - sp[3];
            if ((1.0 + lambda * (sphere_lb - slack)) * nf >= best) continue;
            const double dist2 = triangle_dist2(q, &entry_triangles_[9 * j]);
            const double cost = (1.0 + lambda * std::sqrt(dist2)) * nf;  // face_cost
            if (cost < best) {
              best = cost;
              r = best / dist_factor - 1.0;
              r2 = r * r * (1.0 + 1e-12);
            }
          }
        }
      }
    }
  }
  return best;
}

Eigen::VectorXd TranslationCostCpu::evaluate(const SwatchDistanceGrid& grid,
                                             const TranslationCostProblem& problem) {
  validate_translation_cost_problem(problem);
  const Eigen::Index P = problem.points.rows(), T = problem.offsets.rows();
  std::vector<double> minima(static_cast<std::size_t>(P * T));
  tbb::parallel_for(
      tbb::blocked_range<Eigen::Index>(0, P * T), [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
          const Eigen::Index t = i / P, p = i % P;
          const Vector3d q = problem.points.row(p) - problem.offsets.row(t);
          minima[i] = grid.min_face_cost(q, problem.point_normals.row(p), problem.lambda);
        }
      });
  return sum_per_offset(minima, P, T);
}

Eigen::VectorXd translation_cost_brute_force(const MatrixX3d& V, const MatrixX3i& F,
                                             const TranslationCostProblem& problem) {
  validate_translation_cost_problem(problem);
  MQ_CHECK(F.rows() > 0, InvalidInput, "translation cost: the swatch has no faces");
  MQ_CHECK(V.allFinite(), InvalidInput,
           "translation cost: swatch vertices contain NaN or infinite values");
  MQ_CHECK(F.minCoeff() >= 0 && F.maxCoeff() < V.rows(), InvalidInput,
           "translation cost: face index out of range [0, ", V.rows(), ")");
  const MatrixX3d FN = mq::face_normals(V, F);
  const Eigen::Index P = problem.points.rows(), T = problem.offsets.rows();
  std::vector<double> minima(static_cast<std::size_t>(P * T));
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, P * T),
                    [&](const tbb::blocked_range<Eigen::Index>& r) {
                      for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
                        const Eigen::Index t = i / P, p = i % P;
                        const Vector3d q = problem.points.row(p) - problem.offsets.row(t);
                        const Vector3d n = problem.point_normals.row(p);
                        double best = kInf;
                        for (Eigen::Index f = 0; f < F.rows(); ++f) {
                          const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
                          const double d2 = point_triangle_squared_distance<double>(q, a, b, c);
                          best = std::min(best, face_cost(d2, n, FN.row(f).data(), problem.lambda));
                        }
                        minima[i] = best;
                      }
                    });
  return sum_per_offset(minima, P, T);
}

int best_offset(const Eigen::VectorXd& costs) {
  MQ_CHECK(costs.size() > 0, InvalidInput, "best offset: no costs");
  MQ_CHECK(!costs.hasNaN(), InvalidInput, "best offset: costs contain NaN");
  const double m = costs.minCoeff();
  const double tol = 1e-6 * std::abs(m);
  for (Eigen::Index i = 0; i < costs.size(); ++i)
    if (costs(i) <= m + tol) return static_cast<int>(i);
  MQ_ASSERT(false);
  return -1;
}

}  // namespace mq
