// Straightest geodesics on a triangle mesh (Polthier and Schmies 1998): from a point inside a
// face, walk straight within each face and, across an edge, unfold the direction into the next
// face's plane keeping its angle to the edge. The discrete exponential map: a tangent offset at
// a point becomes a point on the surface at that distance along the surface.
//
// Why (issue 23, "even elements"): an element carried onto the surface through a layout takes
// every distortion the layout has across it (teardrops around cones); placed as a rigid copy
// whose offsets from its centre are walked along the surface, it is bent by the surface only.
#pragma once

#include "core/mesh/mesh.h"

namespace mq {

// Walks from the point with barycentric coordinates `bary` in `face` along the tangent vector
// `t` (3D; its component along the face normal is ignored) for the length of its in-plane
// part. On return face and bary hold the end point (bary >= 0, summing to 1).
//   V #V by 3, F #F by 3, TT = face_adjacency: #F by 3, TT(f,k) across the edge from corner k
//   to corner k+1, -1 at a boundary or non-manifold edge
// Returns false, leaving face and bary at the last point reached, when the walk meets a
// boundary or non-manifold edge, a degenerate face, or takes more than max_faces faces.
bool straightest_walk(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3i& TT, int& face,
                      Vector3d& bary, const Vector3d& t, int max_faces = 512);

}  // namespace mq
