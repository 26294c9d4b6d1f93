#include "core/overlap_region.h"

namespace mq {

OverlapRegion::OverlapRegion(const SynthesisGrid& grid, Vector2d patch_lo, Vector2d patch_hi)
    : grid_(grid), lo_(patch_lo), hi_(patch_hi) {
  processed_.resize(grid.num_cells());
  for (int i = 0; i < grid.num_cells(); ++i) processed_[i] = grid.processed(grid.cell(i));
}

bool OverlapRegion::contains(double x, double y) const {
  if (!in_patch(x, y)) return false;
  const Cell c = grid_.cell_of(x, y);
  return grid_.contains(c) && processed_[grid_.index(c)] != 0;
}

}  // namespace mq
