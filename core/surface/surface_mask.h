// Where a surface texture is wanted (issue 25, `meshquilt surface --mask`): the base is quilted
// as usual, then whole elements over the rest are dropped, so that none is cut at the mask's
// border; coverage is then judged over the mask alone. Vines grow within it instead
// (SurfaceQuiltingOptions::region, mask_faces): a stem kept whole would run on far past it. Its
// file is read by core/surface/vertex_map_io.
#pragma once

#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/surface/surface_quilting.h"

namespace mq {

// One of the two is set: a weight per base vertex in [0, 1], the mask being where the weight
// interpolated linearly across the faces is >= 0.5; or a flag per base face.
struct SurfaceMask {
  Eigen::VectorXd vertex_weight;  // #V(base), or empty
  std::vector<char> face;         // #F(base), or empty
  // Whether the point with barycentric coordinates b on face f of the base lies in the mask.
  bool contains(const TriMesh& base, int f, const Vector3d& b) const;
};

// Per face of quilt.base: whether its centroid lies in the mask, located on `base` (the base
// as given, which the mask describes) by its closest point: exact where quilt.base is a
// refinement of it, the nearest point of it under a simplified proxy.
std::vector<char> mask_quilt_faces(const SurfaceMask& mask, const TriMesh& base,
                                   const SurfaceQuilt& quilt);
// The same for the faces of `refined` (a refinement of base, or a proxy of it).
std::vector<char> mask_faces(const SurfaceMask& mask, const TriMesh& base, const TriMesh& refined);

// The share of the base's area (the base as given) in the mask, sampled at four points of each
// face (its centroid and the middles of its corners' thirds): what the job's face estimate is
// multiplied by when a mask is given (issue 25: the estimate ignored the mask). In [0, 1].
double masked_area_share(const SurfaceMask& mask, const TriMesh& base);

// Drops the elements most of whose vertices lie above faces of quilt.base not in `faces`
// (#F(quilt.base)): whole elements go and none is cut, so the border has no clipped ones, and
// what is kept reaches at most about one element past the mask. Returns how many were dropped.
int drop_unmasked_elements(SurfaceQuilt& quilt, const std::vector<char>& faces);

}  // namespace mq
