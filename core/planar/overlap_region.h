// The overlapping region of paper section 2.5: where a newly placed swatch patch covers output
// that was already synthesised. Planar quilting knows "already synthesised" from its grid cells,
// surface quilting from its base triangles; both give it as a predicate over the patch plane.
#pragma once

#include <functional>

#include "core/mesh/mesh.h"

namespace mq {

class OverlapRegion {
 public:
  // Whether the point (x, y) of the patch plane lies over output synthesised before this patch.
  using ProcessedTest = std::function<bool(double x, double y)>;

  // patch_lo, patch_hi: the xy footprint of the translated swatch. `processed` must describe the
  // output before this patch is merged (take a snapshot if the caller's state changes).
  OverlapRegion(const Vector2d& patch_lo, const Vector2d& patch_hi, ProcessedTest processed)
      : lo_(patch_lo), hi_(patch_hi), processed_(std::move(processed)) {}

  // Inside the patch footprint and over synthesised output.
  bool contains(double x, double y) const { return in_patch(x, y) && processed_(x, y); }
  bool contains(const Vector3d& p) const { return contains(p.x(), p.y()); }
  // Inside the patch footprint (synthesised or not).
  bool in_patch(double x, double y) const {
    return x >= lo_.x() && y >= lo_.y() && x <= hi_.x() && y <= hi_.y();
  }
  const Vector2d& patch_lo() const { return lo_; }
  const Vector2d& patch_hi() const { return hi_; }

 private:
  Vector2d lo_, hi_;
  ProcessedTest processed_;
};

}  // namespace mq
