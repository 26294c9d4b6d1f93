// The overlapping region of paper section 2.5: where a newly placed swatch patch covers output
// cells that were already processed.
#pragma once

#include "core/mesh.h"
#include "core/synthesis_grid.h"

namespace mq {

class OverlapRegion {
 public:
  // patch_lo, patch_hi: the xy footprint of the translated swatch. The grid's processed flags
  // are read at construction and must describe the output before this patch was merged.
  OverlapRegion(const SynthesisGrid& grid, Vector2d patch_lo, Vector2d patch_hi);

  // Inside the patch footprint and over a processed cell.
  bool contains(double x, double y) const;
  bool contains(const Vector3d& p) const { return contains(p.x(), p.y()); }
  // Inside the patch footprint (processed or not).
  bool in_patch(double x, double y) const {
    return x >= lo_.x() && y >= lo_.y() && x <= hi_.x() && y <= hi_.y();
  }
  const Vector2d& patch_lo() const { return lo_; }
  const Vector2d& patch_hi() const { return hi_; }

 private:
  const SynthesisGrid& grid_;
  std::vector<unsigned char> processed_;
  Vector2d lo_, hi_;
};

}  // namespace mq
