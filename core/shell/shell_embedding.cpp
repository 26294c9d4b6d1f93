#include "core/shell/shell_embedding.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"

namespace mq {

ShellEmbedding::ShellEmbedding(const ShellMap& map)
    : shell_V_(map.problem().shell_V),
      texture_V_(map.problem().texture_V),
      T_(map.problem().T),
      UV_(map.atlas().UV),
      FUV_(map.atlas().FUV),
      face_chart_(map.atlas().face_chart),
      height_(map.height()) {
  const int nt = static_cast<int>(T_.rows());
  inverse_.resize(nt);
  tbb::parallel_for(tbb::blocked_range<int>(0, nt), [&](const tbb::blocked_range<int>& r) {
    for (int t = r.begin(); t != r.end(); ++t) {
      Eigen::Matrix3d E;
      for (int c = 0; c < 3; ++c)
        E.col(c) = (texture_V_.row(T_(t, c + 1)) - texture_V_.row(T_(t, 0))).transpose();
      inverse_[t] = E.inverse();  // texture tets are positive (ShellMap keeps them so)
    }
  });
  // Per-chart grids over the (u, v) boxes of the chart's tets, about one tet per cell.
  const int nc = map.atlas().num_charts;
  std::vector<std::vector<int>> chart_tets(nc);
  for (int t = 0; t < nt; ++t) chart_tets[face_chart_[t / 3]].push_back(t);
  grids_.resize(nc);
  tbb::parallel_for(0, nc, [&](int c) {
    Grid& g = grids_[c];
    const std::vector<int>& ts = chart_tets[c];
    Vector2d lo = Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    std::vector<Eigen::Vector4d> box(ts.size());
    for (std::size_t i = 0; i < ts.size(); ++i) {
      Vector2d a = texture_V_.row(T_(ts[i], 0)).head<2>().transpose(), b = a;
      for (int k = 1; k < 4; ++k) {
        a = a.cwiseMin(texture_V_.row(T_(ts[i], k)).head<2>().transpose());
        b = b.cwiseMax(texture_V_.row(T_(ts[i], k)).head<2>().transpose());
      }
      box[i] << a, b;
      lo = lo.cwiseMin(a);
      hi = hi.cwiseMax(b);
    }
    const Vector2d ext = (hi - lo).cwiseMax(1e-300);
    const double cells = std::max(1.0, static_cast<double>(ts.size()));
    g.cell = std::sqrt(ext.x() * ext.y() / cells);
    if (!(g.cell > 0.0)) g.cell = std::max(ext.x(), ext.y());
    g.nx = std::clamp(static_cast<int>(ext.x() / g.cell) + 1, 1, 4096);
    g.ny = std::clamp(static_cast<int>(ext.y() / g.cell) + 1, 1, 4096);
    g.cell = std::max(ext.x() / g.nx, ext.y() / g.ny) * (1.0 + 1e-9);
    g.lo = lo;
    auto index = [&](double v, double l, int n) {
      return std::clamp(static_cast<int>((v - l) / g.cell), 0, n - 1);
    };
    g.offsets.assign(static_cast<std::size_t>(g.nx) * g.ny + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<int> fill(g.offsets.begin(), g.offsets.end() - 1);
      for (std::size_t i = 0; i < ts.size(); ++i) {
        const int x0 = index(box[i][0], lo.x(), g.nx), x1 = index(box[i][2], lo.x(), g.nx);
        const int y0 = index(box[i][1], lo.y(), g.ny), y1 = index(box[i][3], lo.y(), g.ny);
        for (int x = x0; x <= x1; ++x)
          for (int y = y0; y <= y1; ++y) {
            const int cell = x * g.ny + y;
            if (pass == 0)
              ++g.offsets[cell + 1];
            else
              g.tets[fill[cell]++] = ts[i];
          }
      }
      if (pass == 0) {
        for (std::size_t k = 1; k < g.offsets.size(); ++k) g.offsets[k] += g.offsets[k - 1];
        g.tets.resize(g.offsets.back());
      }
    }
  });
}

MatrixX3d ShellEmbedding::embed(const LocalCoordinates& P, Eigen::VectorXi* tet_out) const {
  const int np = P.size();
  MQ_CHECK(P.bary.rows() == np && P.height.size() == np, InvalidInput, "shell embedding: ", np,
           " faces but ", P.bary.rows(), " barycentric rows and ", P.height.size(), " heights");
  const int nf = static_cast<int>(FUV_.rows());
  for (int i = 0; i < np; ++i) {
    MQ_CHECK(P.face(i) >= 0 && P.face(i) < nf, InvalidInput, "shell embedding: point ", i,
             " has face ", P.face(i), " outside [0, ", nf, ")");
    MQ_CHECK(P.bary.row(i).allFinite() && P.bary.row(i).minCoeff() >= -1e-9 &&
                 std::abs(P.bary.row(i).sum() - 1.0) <= 1e-6,
             InvalidInput, "shell embedding: point ", i, " has invalid barycentric coordinates");
    MQ_CHECK(std::isfinite(P.height(i)) && P.height(i) >= -1e-9 * height_ &&
                 P.height(i) <= height_ * (1.0 + 1e-9),
             InvalidInput, "shell embedding: point ", i, " has height ", P.height(i),
             " outside [0, ", height_, "]");
  }
  MatrixX3d out(np, 3);
  if (tet_out) tet_out->resize(np);
  auto bary_in = [&](int t, const Vector3d& p, Eigen::Vector4d& b) {
    const Vector3d x = inverse_[t] * (p - texture_V_.row(T_(t, 0)).transpose());
    b << 1.0 - x.sum(), x;
    return b.minCoeff();
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, np), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const int f = P.face(i);
      Vector2d uv = Vector2d::Zero();
      for (int k = 0; k < 3; ++k) uv += P.bary(i, k) * UV_.row(FUV_(f, k)).transpose();
      const Vector3d p(uv.x(), uv.y(), P.height(i));
      int best = -1;
      double best_min = -std::numeric_limits<double>::infinity();
      Eigen::Vector4d best_b, b;
      auto consider = [&](int t) {
        const double mn = bary_in(t, p, b);
        if (mn > best_min || (mn == best_min && t < best)) {
          best_min = mn;
          best = t;
          best_b = b;
        }
      };
      for (int k = 0; k < 3; ++k) consider(3 * f + k);
      if (best_min < -1e-12) {
        // Shifted out of its own prism by the optimised offset (u, v): search the chart.
        const Grid& g = grids_[face_chart_[f]];
        const int x = std::clamp(static_cast<int>((uv.x() - g.lo.x()) / g.cell), 0, g.nx - 1);
        const int y = std::clamp(static_cast<int>((uv.y() - g.lo.y()) / g.cell), 0, g.ny - 1);
        const int cell = x * g.ny + y;
        for (int a = g.offsets[cell]; a < g.offsets[cell + 1]; ++a) consider(g.tets[a]);
      }
      // Rounding only: clamp to the tet (the chart's texture tets tile footprint x [0, H]).
      best_b = best_b.cwiseMax(0.0);
      best_b /= best_b.sum();
      Vector3d q = Vector3d::Zero();
      for (int c = 0; c < 4; ++c) q += best_b(c) * shell_V_.row(T_(best, c)).transpose();
      out.row(i) = q;
      if (tet_out) (*tet_out)(i) = best;
    }
  });
  return out;
}

MatrixX3d normal_displacement(const MatrixX3d& V, const MatrixX3i& F, const LocalCoordinates& P) {
  return normal_displacement(V, F, vertex_normals(V, F), P);
}

MatrixX3d normal_displacement(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N,
                              const LocalCoordinates& P) {
  const int np = P.size();
  MQ_CHECK(N.rows() == V.rows(), InvalidInput, "normal displacement: ", N.rows(),
           " directions for ", V.rows(), " vertices");
  MQ_CHECK(P.bary.rows() == np && P.height.size() == np, InvalidInput,
           "normal displacement: mismatched point arrays");
  MQ_CHECK(V.allFinite() && P.bary.allFinite() && P.height.allFinite(), InvalidInput,
           "normal displacement: non-finite input");
  MQ_CHECK(F.rows() == 0 || (F.minCoeff() >= 0 && F.maxCoeff() < V.rows()), InvalidInput,
           "normal displacement: face index out of range");
  for (int i = 0; i < np; ++i)
    MQ_CHECK(P.face(i) >= 0 && P.face(i) < F.rows(), InvalidInput, "normal displacement: point ", i,
             " has face ", P.face(i), " out of range");
  MatrixX3d out(np, 3);
  std::vector<char> bad(np, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, np), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      Vector3d x = Vector3d::Zero(), n = Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        x += P.bary(i, k) * V.row(F(P.face(i), k)).transpose();
        n += P.bary(i, k) * N.row(F(P.face(i), k)).transpose();
      }
      const double len = n.norm();
      bad[i] = !(len > 1e-12);
      out.row(i) = x + (bad[i] ? 0.0 : P.height(i) / len) * n;
    }
  });
  for (int i = 0; i < np; ++i)
    MQ_CHECK(!bad[i], TopologyError, "normal displacement: the interpolated normal of point ", i,
             " vanishes");
  return out;
}

}  // namespace mq
