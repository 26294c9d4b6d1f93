// The triangle mesh type shared by every stage, and the Eigen shapes used throughout.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <vector>

namespace mq {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kTwoPi = 6.283185307179586476925286766559;

// Row-major so that rows are contiguous xyz triples: they go to Embree and OpenCL unchanged.
using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX2d = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
using MatrixX3f = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Vector3d = Eigen::Vector3d;
using Vector2d = Eigen::Vector2d;

// A triangle mesh.
//   V  #V by 3 vertex positions
//   F  #F by 3 vertex indices (0-based, counter-clockwise seen from outside)
//   N  optional: #V by 3 unit vertex normals, or empty
//   kinds      optional: names of the kinds of element (section 2.1's elements: "ring",
//              "thread_x", "vine", "leaf", ...), or empty when the mesh has none
//   face_kind  #F indices into kinds when kinds is not empty (otherwise ignored); an element
//              (connected component) has one kind
struct TriMesh {
  MatrixX3d V;
  MatrixX3i F;
  MatrixX3d N;
  std::vector<std::string> kinds;
  std::vector<int> face_kind;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }
  bool empty() const { return F.rows() == 0; }
};

// Axis-aligned bounding box.
struct BoundingBox {
  Vector3d min = Vector3d::Constant(std::numeric_limits<double>::infinity());
  Vector3d max = Vector3d::Constant(-std::numeric_limits<double>::infinity());

  bool empty() const { return !(min.array() <= max.array()).all(); }
  Vector3d extent() const { return empty() ? Vector3d::Zero() : Vector3d(max - min); }
  Vector3d center() const { return 0.5 * (min + max); }
  void extend(const Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};

}  // namespace mq
