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

  triangles_.resize(9 * F.rows());
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) triangles_[9 * f + 3 * k + a] = V(F(f, k), a);
  const MatrixX3d FN = mq::face_normals(V, F);
  face_normals_.assign(FN.data(), FN.data() + FN.size());

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
  auto cell_range = [&](Eigen::Index f, Eigen::Vector3i& lo, Eigen::Vector3i& hi) {
    for (int a = 0; a < 3; ++a) {
      double mn = kInf, mx = -kInf;
      for (int k = 0; k < 3; ++k) {
        mn = std::min(mn, triangles_[9 * f + 3 * k + a]);
        mx = std::max(mx, triangles_[9 * f + 3 * k + a]);
      }
      lo(a) = std::clamp(static_cast<int>(std::floor((mn - origin_(a)) / h)), 0, dims_(a) - 1);
      hi(a) = std::clamp(static_cast<int>(std::floor((mx - origin_(a)) / h)), 0, dims_(a) - 1);
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

  cell_cones_.assign(4 * std::size_t(num_cells), 0.0);
  for (int c = 0; c < num_cells; ++c) {
    Vector3d mean = Vector3d::Zero();
    for (int j = cell_start_[c]; j < cell_start_[c + 1]; ++j)
      mean += Vector3d(&face_normals_[3 * cell_faces_[j]]);
    const double len = mean.norm();
    const Vector3d dir = len > 1e-12 ? Vector3d(mean / len) : Vector3d::Zero();
    double r = 0.0;
    for (int j = cell_start_[c]; j < cell_start_[c + 1]; ++j)
      r = std::max(r, (Vector3d(&face_normals_[3 * cell_faces_[j]]) - dir).norm());
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
  fnv1a(fp, triangles_.data(), sizeof(double) * triangles_.size());
  fnv1a(fp, face_normals_.data(), sizeof(double) * face_normals_.size());
  fnv1a(fp, cell_start_.data(), sizeof(int) * cell_start_.size());
  fnv1a(fp, cell_faces_.data(), sizeof(int) * cell_faces_.size());
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
  const double slack = 1e-9;
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
      if (1.0 + lambda * (lb - slack) * h >= best) break;
    }
    const int x0 = std::max(0, c[0] - k), x1 = std::min(dims_(0) - 1, c[0] + k);
    const int y0 = std::max(0, c[1] - k), y1 = std::min(dims_(1) - 1, c[1] + k);
    for (int x = x0; x <= x1; ++x) {
      const double gx = gap(0, x);
      for (int y = y0; y <= y1; ++y) {
        const double gy = gap(1, y);
        const bool shell = std::abs(x - c[0]) == k || std::abs(y - c[1]) == k;
        // Inside the ring's x/y shell every z is on the ring; otherwise only the two z caps.
        const int zs[2] = {c[2] - k, c[2] + k};
        const int z0 = shell ? std::max(0, c[2] - k) : 0;
        const int z1 = shell ? std::min(dims_(2) - 1, c[2] + k) : (k > 0 ? 1 : 0);
        for (int zi = z0; zi <= z1; ++zi) {
          const int z = shell ? zi : zs[zi];
          if (z < 0 || z >= dims_(2)) continue;
          const double gz = gap(2, z);
          const double dist_factor =
              1.0 + lambda * (std::sqrt(gx * gx + gy * gy + gz * gz) - slack) * h;
          if (dist_factor >= best) continue;
          const int cell = (z * dims_(1) + y) * dims_(0) + x;
          const double* cone = &cell_cones_[4 * cell];
          const double cx = n(0) - cone[0], cy = n(1) - cone[1], cz = n(2) - cone[2];
          const double cone_lb = std::sqrt(cx * cx + cy * cy + cz * cz) - cone[3];
          if (dist_factor * (1.0 + std::max(0.0, cone_lb)) >= best) continue;
          for (int j = cell_start_[cell]; j < cell_start_[cell + 1]; ++j) {
            const int f = cell_faces_[j];
            const double nf = normal_factor(n, &face_normals_[3 * f]);
            if (dist_factor * nf >= best) continue;
            const double d2 = triangle_dist2(q, &triangles_[9 * f]);
            best = std::min(best, (1.0 + lambda * std::sqrt(d2)) * nf);  // face_cost
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
