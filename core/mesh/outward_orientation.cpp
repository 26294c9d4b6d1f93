#include "core/mesh/outward_orientation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"

namespace mq {
namespace {

constexpr int kSamples = 32;
constexpr double kInwardBelow = -0.05;

// Signed solid angle of triangle abc seen from p (van Oosterom and Strackee 1983): positive when
// p lies on the side its normal (b - a) x (c - a) points away from.
double solid_angle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d x = a - p, y = b - p, z = c - p;
  const double lx = x.norm(), ly = y.norm(), lz = z.norm();
  const double det = x.dot(y.cross(z));
  const double div = lx * ly * lz + x.dot(y) * lz + x.dot(z) * ly + y.dot(z) * lx;
  return 2 * std::atan2(det, div);
}

}  // namespace

double mean_surface_winding(const MatrixX3d& V, const MatrixX3i& F, const std::vector<int>& faces) {
  if (faces.empty()) return 0.0;
  const auto corner = [&](int f, int k) { return Vector3d(V.row(F(f, k)).transpose()); };
  // Samples spread evenly over the area: the faces at the midpoints of kSamples equal slices of
  // the cumulative area (in face order).
  std::vector<double> cumulative(faces.size());
  double total = 0;
  for (size_t i = 0; i < faces.size(); ++i) {
    const int f = faces[i];
    total += 0.5 * (corner(f, 1) - corner(f, 0)).cross(corner(f, 2) - corner(f, 0)).norm();
    cumulative[i] = total;
  }
  if (!(total > 0)) return 0.0;
  const int n = static_cast<int>(std::min<size_t>(kSamples, faces.size()));
  std::vector<int> samples;
  for (int i = 0; i < n; ++i) {
    const double target = (i + 0.5) / n * total;
    const size_t at = static_cast<size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin());
    const int f = faces[std::min(at, faces.size() - 1)];
    if (samples.empty() || samples.back() != f) samples.push_back(f);
  }
  std::vector<double> w(samples.size(), 0.0);
  tbb::parallel_for(size_t{0}, samples.size(), [&](size_t s) {
    const int f = samples[s];
    const Vector3d c = (corner(f, 0) + corner(f, 1) + corner(f, 2)) / 3;
    double sum = 0;  // in face order: the same sum whatever the threads
    for (const int g : faces)
      if (g != f) sum += solid_angle(c, corner(g, 0), corner(g, 1), corner(g, 2));
    w[s] = sum / (2 * kTwoPi);
  });
  double mean = 0;
  for (const double x : w) mean += x;
  return mean / static_cast<double>(w.size());
}

int orient_outward(TriMesh& mesh) {
  std::vector<int> fc;
  const int n = connected_components(mesh.F, mesh.num_vertices(), fc);
  const std::vector<std::vector<int>> groups = component_faces(fc, n);
  int flipped = 0;
  for (int c = 0; c < n; ++c) {
    const std::vector<int>& faces = groups[static_cast<size_t>(c)];
    if (!(mean_surface_winding(mesh.V, mesh.F, faces) < kInwardBelow)) continue;
    ++flipped;
    for (const int f : faces) std::swap(mesh.F(f, 1), mesh.F(f, 2));
  }
  return flipped;
}

}  // namespace mq
