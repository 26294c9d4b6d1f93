#include "core/planar/synthesis_grid.h"

#include <algorithm>
#include <cmath>

#include "core/common/errors.h"

namespace mq {

SynthesisGrid::SynthesisGrid(const Vector2d& origin, double cell_size, int nx, int ny)
    : origin_(origin), cell_size_(cell_size), nx_(nx), ny_(ny) {
  MQ_CHECK(std::isfinite(cell_size) && cell_size > 0, InvalidInput,
           "grid cell size must be positive and finite, got ", cell_size);
  MQ_CHECK(origin.allFinite(), InvalidInput, "grid origin is not finite");
  MQ_CHECK(nx > 0 && ny > 0, InvalidInput, "grid must have at least one cell, got ", nx, " x ", ny);
  MQ_CHECK(static_cast<long long>(nx) * ny <= (1LL << 26), InvalidInput, "grid of ", nx, " x ", ny,
           " cells is too large; use a larger cell size");
  processed_.assign(static_cast<size_t>(nx) * ny, 0);
}

Cell SynthesisGrid::cell_of(double x, double y) const {
  return {static_cast<int>(std::floor((x - origin_.x()) / cell_size_)),
          static_cast<int>(std::floor((y - origin_.y()) / cell_size_))};
}

OverlapRegion::ProcessedTest SynthesisGrid::processed_snapshot() const {
  return [origin = origin_, cell = cell_size_, nx = nx_, ny = ny_, flags = processed_](double x,
                                                                                       double y) {
    const int cx = static_cast<int>(std::floor((x - origin.x()) / cell));
    const int cy = static_cast<int>(std::floor((y - origin.y()) / cell));
    return cx >= 0 && cy >= 0 && cx < nx && cy < ny && flags[cy * nx + cx] != 0;
  };
}

int SynthesisGrid::num_processed() const {
  return static_cast<int>(std::count(processed_.begin(), processed_.end(), 1));
}

bool SynthesisGrid::next_seed(Cell& seed) const {
  int best = -1, best_index = -1;
  for (int y = 0; y < ny_; ++y)
    for (int x = 0; x < nx_; ++x) {
      if (processed_[y * nx_ + x]) continue;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Cell n{x + dx, y + dy};
          if ((dx || dy) && contains(n) && processed(n)) ++count;
        }
      if (count > best) {
        best = count;
        best_index = y * nx_ + x;
      }
    }
  if (best_index < 0) return false;
  seed = cell(best_index);
  return true;
}

std::vector<std::vector<int>> SynthesisGrid::assign_faces(const MatrixX3d& V,
                                                          const MatrixX3i& F) const {
  std::vector<std::vector<int>> cells(num_cells());
  for (int f = 0; f < F.rows(); ++f) {
    double x0 = V(F(f, 0), 0), x1 = x0, y0 = V(F(f, 0), 1), y1 = y0;
    for (int k = 1; k < 3; ++k) {
      x0 = std::min(x0, V(F(f, k), 0));
      x1 = std::max(x1, V(F(f, k), 0));
      y0 = std::min(y0, V(F(f, k), 1));
      y1 = std::max(y1, V(F(f, k), 1));
    }
    const Cell lo = cell_of(x0, y0), hi = cell_of(x1, y1);
    for (int y = std::max(lo.y, 0); y <= std::min(hi.y, ny_ - 1); ++y)
      for (int x = std::max(lo.x, 0); x <= std::min(hi.x, nx_ - 1); ++x)
        cells[y * nx_ + x].push_back(f);
  }
  return cells;
}

}  // namespace mq
