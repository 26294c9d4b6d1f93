// A flattened local patch in the synthesis frame (paper section 3.1): the patch's conformal map
// rotated so that the guidance field points along +x at the seed and translated so that the
// seed's centroid is the origin. The planar steps of section 2 run in this frame; local
// coordinates (base face, barycentric coordinates) go in and out of it here.
#pragma once

#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/mesh/closest_point_query.h"
#include "core/mesh/mesh.h"
#include "core/surface/local_patch.h"

namespace mq {

class PatchFrame {
 public:
  // `patch` grown on `base` (its first face the seed), `direction` the guidance field at the seed
  // (a 3D tangent). device: where the BVH for points beyond the patch is built when first needed.
  // `size` (> 0): the element size wanted around the seed, as a factor of the swatch's (a size
  // map's, issue 25); the frame is the surface divided by it, so that the swatch, unchanged in
  // the frame, lands at that size on the surface. `base` and `device` must outlive the frame.
  // Throws nothing.
  PatchFrame(const TriMesh& base, LocalPatch patch, const Vector3d& direction,
             const EmbreeDevice& device, double size = 1);

  const LocalPatch& patch() const { return patch_; }
  // Surface length per frame length (the size given): a height h over the base is h / size in
  // the frame.
  double size() const { return size_; }
  // #V(patch) by 2: the patch's vertices in the frame.
  const MatrixX2d& uv() const { return uv_; }
  // The patch face that base face `base_face` is, or -1.
  int local_face(int base_face) const;

  // Frame position of a local coordinate; beyond the patch, through the nearest patch face.
  Vector2d to_frame(int base_face, const Vector3d& bary) const;

  // The patch face containing frame point q (true) or the nearest one (false, with barycentric
  // coordinates extrapolating it).
  bool locate(const Vector2d& q, int& face, Vector3d& bary) const;

  // Frame position of the centroid of patch face f.
  Vector2d face_centroid(int f) const;

  // Minimum distance from q to the patch's boundary in the frame.
  double distance_to_border(const Vector2d& q) const;

 private:
  void build_grid();

  const TriMesh& base_;
  LocalPatch patch_;
  MatrixX2d uv_;
  double size_ = 1;
  std::unordered_map<int, int> local_of_;
  Vector2d lo_ = Vector2d::Zero();
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
  std::vector<std::pair<int, int>> border_;
  const EmbreeDevice& device_;
  mutable std::unique_ptr<ClosestPointQuery> query_;
};

}  // namespace mq
