// Per-face and per-vertex measures of a triangle mesh: normals, areas, bounding boxes.
#pragma once

#include "core/mesh/mesh.h"

namespace mq {

// Unit face normals.
//   V  #V by 3, F  #F by 3
// Returns #F by 3; a degenerate (zero-area) face gets the zero vector.
MatrixX3d face_normals(const MatrixX3d& V, const MatrixX3i& F);

// Unit vertex normals, the area-weighted average of incident face normals.
// Returns #V by 3; an isolated vertex or one whose faces cancel gets the zero vector.
MatrixX3d vertex_normals(const MatrixX3d& V, const MatrixX3i& F);

// Triangle areas. Returns #F.
Eigen::VectorXd face_areas(const MatrixX3d& V, const MatrixX3i& F);

// Total surface area.
double surface_area(const MatrixX3d& V, const MatrixX3i& F);

// Bounding box of the referenced vertices (vertices used by at least one face); of all
// vertices when F is empty.
BoundingBox bounding_box(const MatrixX3d& V, const MatrixX3i& F);

// Bounding box of all rows of V.
BoundingBox bounding_box(const MatrixX3d& V);

// Mean edge length over all face edges (each interior edge counted twice); 0 when F is empty.
double mean_edge_length(const MatrixX3d& V, const MatrixX3i& F);

}  // namespace mq
