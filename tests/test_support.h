// Shared helpers for the test programs: data paths and small procedural fixtures.
#pragma once

#include <algorithm>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq::test {

// Uniform doubles from a 64-bit generator (its top 53 bits): in [0, 1), and in [lo, hi).
inline double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}
inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * uniform01(rng);
}

// The upper median of v (its element at index size / 2 once sorted; 0 when v is empty).
inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Absolute path of a file in ../shared/data (e.g. "base/bunny_igl_7k.off").
std::string shared_data(const std::string& relative);

// Absolute path of a base exported by headless Blender (tests/data/export_blender_bases.py, the
// build's `blender_bases` target), e.g. "uv_sphere_32x16.obj".
std::string blender_base(const std::string& name);

// The bytes of a file (empty when it cannot be read), and a file written with `text`.
std::string slurp(const std::string& path);
void spit(const std::string& path, const std::string& text);

// A fresh, empty temporary directory unique to the calling test.
std::string temp_dir();

// Closed, outward-oriented unit cube [0,1]^3: 8 vertices, 12 faces.
TriMesh unit_cube();

// Closed torus around the z axis: major radius R, minor radius r, n x m quads split in two.
TriMesh torus(double R, double r, int n, int m);

// Open regular grid in the z = 0 plane over [0,w]x[0,h], nx by ny quads split in two.
TriMesh plane_grid(double w, double h, int nx, int ny);

// A UV sphere as Blender's "Add > UV Sphere" makes it: `segments` around the z axis, `rings`
// from pole to pole, quads split in two and a fan of triangles at each pole (where `segments`
// thin triangles meet), radius r, closed and outward.
TriMesh uv_sphere(double r, int segments, int rings);

// Open cylinder of radius r around the z axis over [0, h], n segments around, m along, faces
// counter-clockwise seen from outside.
TriMesh open_cylinder(double r, double h, int n, int m);

// Expects every stride-th face of `fine`, a refinement of `coarse`, to map through
// to_coarse(face, barycentric) onto the same 3D point of `coarse` (within 1e-12), with
// barycentric coordinates that sum to 1 and are not negative.
void expect_same_points_on_coarse(const TriMesh& fine, const TriMesh& coarse, int stride,
                                  const std::function<void(int&, Vector3d&)>& to_coarse);

}  // namespace mq::test
