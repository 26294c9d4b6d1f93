#include "core/shell/surface_coverage.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/embree_device.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/point_triangle.h"
#include "core/planar/quilt_elements.h"

namespace mq {

namespace {

// Distance from c to the part of triangle abc in the half-space (x - c) . n >= -below: the
// closest point of the whole triangle when it lies there; otherwise the constrained closest
// point lies on the half-space's plane (the distance is convex), so on the segment the plane
// cuts from the triangle. Infinity when the triangle lies wholly outside the half-space.
double clipped_distance(const Vector3d& c, const Vector3d& n, double below, const Vector3d& a,
                        const Vector3d& b, const Vector3d& d) {
  const Vector3d w = closest_point_barycentric<double>(c, a, b, d);
  const Vector3d q = w(0) * a + w(1) * b + w(2) * d;
  if ((q - c).dot(n) >= -below) return (q - c).norm();
  const Vector3d p[3] = {a, b, d};
  double s[3];
  for (int k = 0; k < 3; ++k) s[k] = (p[k] - c).dot(n) + below;  // >= 0 inside
  Vector3d ends[2];
  int m = 0;
  for (int k = 0; k < 3 && m < 2; ++k) {
    const int j = (k + 1) % 3;
    if (s[k] >= 0 && s[j] >= 0) continue;
    if (s[k] >= 0 || s[j] >= 0) {
      const double t = s[k] / (s[k] - s[j]);
      ends[m++] = p[k] + t * (p[j] - p[k]);
    }
  }
  if (m == 0) {
    // Only a vertex touches the plane, or none does.
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k)
      if (s[k] >= 0) best = std::min(best, (p[k] - c).norm());
    return best;
  }
  if (m == 1) return (ends[0] - c).norm();
  const Vector3d e = ends[1] - ends[0];
  const double len2 = e.squaredNorm();
  const double t = len2 > 0 ? std::clamp((c - ends[0]).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (ends[0] + t * e - c).norm();
}

struct Query {
  const TriMesh* output;
  const std::vector<int>* faces;  // the scene's triangles: output faces
  Vector3d c, n;
  double below, radius;
  bool found = false;
};

bool visit(RTCPointQueryFunctionArguments* args) {
  Query& q = *static_cast<Query*>(args->userPtr);
  if (q.found) return false;
  const int f = (*q.faces)[args->primID];
  const MatrixX3d& V = q.output->V;
  const MatrixX3i& F = q.output->F;
  const double d = clipped_distance(q.c, q.n, q.below, V.row(F(f, 0)).transpose(),
                                    V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose());
  if (!(d <= q.radius)) return false;
  q.found = true;
  args->query->radius = 0.0f;  // one is enough: Embree stops descending
  return true;
}

// Some of the output's triangles (`faces`) in an Embree scene (float copies; released with the
// object).
class OutputScene {
 public:
  OutputScene(const EmbreeDevice& device, const TriMesh& output, const std::vector<int>& faces) {
    scene_ = rtcNewScene(device.get());
    device.check("coverage: rtcNewScene");
    MQ_CHECK(scene_, Error, "coverage: Embree returned no scene");
    try {
      // A scene built once for few queries per output face: the fast build.
      rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_LOW);
      RTCGeometry geom = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
          geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), output.V.rows()));
      auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), faces.size()));
      if (!vb || !ib) {
        rtcReleaseGeometry(geom);
        device.check("coverage: rtcSetNewGeometryBuffer");
        MQ_THROW(Error, "coverage: Embree returned no geometry buffer");
      }
      for (Eigen::Index i = 0; i < output.V.rows(); ++i)
        for (int k = 0; k < 3; ++k) vb[3 * i + k] = static_cast<float>(output.V(i, k));
      for (size_t i = 0; i < faces.size(); ++i)
        for (int k = 0; k < 3; ++k) ib[3 * i + k] = static_cast<unsigned>(output.F(faces[i], k));
      rtcCommitGeometry(geom);
      rtcAttachGeometry(scene_, geom);
      rtcReleaseGeometry(geom);
      rtcCommitScene(scene_);
      device.check("coverage: building the Embree BVH");
    } catch (...) {
      rtcReleaseScene(scene_);
      throw;
    }
  }
  ~OutputScene() { rtcReleaseScene(scene_); }
  OutputScene(const OutputScene&) = delete;
  OutputScene& operator=(const OutputScene&) = delete;
  RTCScene get() const { return scene_; }

 private:
  RTCScene scene_ = nullptr;
};

// Cells of a uniform grid keyed by 20 bits per axis (x lowest: three cells along x are
// consecutive keys), clamped to the grid: what the vertex pass and the triangle filter below
// look points up by.
struct CellKeys {
  static constexpr int kCells = 1 << 20;
  Eigen::Array3d origin = Eigen::Array3d::Zero();
  double cell = 1;

  Eigen::Array3i cell_of(const Eigen::Array3d& p) const {
    return ((p - origin) / cell).floor().max(0.0).min(kCells - 1.0).cast<int>();
  }
  static std::uint64_t key(const Eigen::Array3i& c) {
    return (static_cast<std::uint64_t>(c.z()) << 40) | (static_cast<std::uint64_t>(c.y()) << 20) |
           static_cast<std::uint64_t>(c.x());
  }
};

// The output's vertices that faces use, sorted by the cell (one radius wide) they lie in: a
// base point with one of them within the radius on its outer side is covered (a vertex is a
// point of its triangles, and the triangle query would find that one or a nearer point), and
// where every point is, the triangles' BVH is never built (armor job: 2.7M output faces, 3,344
// base faces, all covered). Empty (nothing found) when the grid would need more than 2^20
// cells along an axis.
class VertexGrid {
 public:
  VertexGrid(const TriMesh& output, double radius) {
    const Eigen::Index nv = output.V.rows();
    std::vector<char> used(static_cast<size_t>(nv), 0);
    for (Eigen::Index f = 0; f < output.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) used[static_cast<size_t>(output.F(f, k))] = 1;
    const BoundingBox box = bounding_box(output.V);
    if (!(radius > 0) || !((box.extent() / radius).maxCoeff() < CellKeys::kCells - 2)) return;
    grid_.origin = box.min.array() - radius;
    grid_.cell = radius;
    for (Eigen::Index v = 0; v < nv; ++v)
      if (used[static_cast<size_t>(v)]) {
        const Vector3d p = output.V.row(v).transpose();
        points_.push_back({CellKeys::key(grid_.cell_of(p.array())), p});
      }
    // Whether a vertex covers a point does not depend on the order within a cell.
    tbb::parallel_sort(points_.begin(), points_.end(),
                       [](const Point& a, const Point& b) { return a.key < b.key; });
  }

  // Is a vertex within `radius` (at most the cell) of c with (v - c) . n >= -below?
  bool covers(const Vector3d& c, const Vector3d& n, double radius, double below) const {
    if (points_.empty()) return false;
    const Eigen::Array3i m = grid_.cell_of(c.array());
    if ((m < 1).any() || (m > CellKeys::kCells - 2).any()) return false;
    // One search per row of three cells along x, c's own row first (where a covering vertex
    // most often is).
    for (int row = 0; row < 9; ++row) {
      const int dy = (row + 1) % 3 - 1, dz = (row / 3 + 1) % 3 - 1;
      const std::uint64_t from = CellKeys::key(m + Eigen::Array3i(-1, dy, dz)), to = from + 2;
      auto it = std::lower_bound(points_.begin(), points_.end(), from,
                                 [](const Point& p, std::uint64_t x) { return p.key < x; });
      for (; it != points_.end() && it->key <= to; ++it) {
        const Vector3d d = it->p - c;
        if (d.squaredNorm() <= radius * radius && d.dot(n) >= -below) return true;
      }
    }
    return false;
  }

 private:
  struct Point {
    std::uint64_t key;
    Vector3d p;
  };
  CellKeys grid_;
  std::vector<Point> points_;
};

// The output's triangles whose box, grown by the radius, holds one of the rows of `points`: the
// only ones that can cover them (cup job: the triangle pass for the few centroids no vertex
// covers then builds its BVH over them instead of the whole output). Ascending; a triangle
// whose grown box spans more than 64 cells of the points' grid is taken unchecked.
std::vector<int> triangles_near(const TriMesh& output, const MatrixX3d& points, double radius) {
  const BoundingBox box = bounding_box(points);
  const double grow = radius * (1 + 1e-9) + 1e-300;
  CellKeys grid;
  grid.cell = std::max(grow, box.extent().maxCoeff() / (CellKeys::kCells / 2.0));
  grid.origin = box.min.array() - grid.cell;
  std::vector<std::uint64_t> keys;
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    keys.push_back(CellKeys::key(grid.cell_of(points.row(i).transpose().array())));
  std::sort(keys.begin(), keys.end());
  std::vector<char> near(static_cast<size_t>(output.F.rows()), 0);
  tbb::parallel_for(Eigen::Index(0), output.F.rows(), [&](Eigen::Index f) {
    Eigen::Array3d lo = output.V.row(output.F(f, 0)).transpose().array(), hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.min(output.V.row(output.F(f, k)).transpose().array());
      hi = hi.max(output.V.row(output.F(f, k)).transpose().array());
    }
    lo -= grow;
    hi += grow;
    if ((hi < box.min.array()).any() || (lo > box.max.array()).any()) return;
    const Eigen::Array3i a = grid.cell_of(lo), b = grid.cell_of(hi);
    if ((b - a + 1).cast<std::int64_t>().prod() > 64) {
      near[static_cast<size_t>(f)] = 1;
      return;
    }
    for (int z = a.z(); z <= b.z(); ++z)
      for (int y = a.y(); y <= b.y(); ++y) {
        const auto it = std::lower_bound(keys.begin(), keys.end(), CellKeys::key({a.x(), y, z}));
        if (it != keys.end() && *it <= CellKeys::key({b.x(), y, z})) {
          near[static_cast<size_t>(f)] = 1;
          return;
        }
      }
  });
  std::vector<int> faces;
  for (Eigen::Index f = 0; f < output.F.rows(); ++f)
    if (near[static_cast<size_t>(f)]) faces.push_back(static_cast<int>(f));
  return faces;
}

// Whether base face f is measured: all are without a mask (`faces` empty).
bool counted(const std::vector<char>& faces, Eigen::Index f) {
  return faces.empty() || faces[static_cast<size_t>(f)] != 0;
}

// Per base face (those counted): whether output geometry lies within the radius of its
// centroid on its outer side (visit: the first triangle found ends the query).
//   C, N  #F(base) by 3 face centroids and unit normals
std::vector<unsigned char> covered_faces(const MatrixX3d& C, const MatrixX3d& N,
                                         const TriMesh& output, const std::vector<int>& scene_faces,
                                         RTCScene scene, double radius, double below,
                                         const std::vector<char>& faces) {
  std::vector<unsigned char> covered(static_cast<size_t>(C.rows()), 0);
  const BoundingBox box = bounding_box(output.V);
  // Float bounds and a float query point: the radius handed to Embree is enlarged far above
  // their rounding; every triangle is then measured exactly in double.
  const double slack = 1e-6 * (box.extent().norm() + std::max(box.min.cwiseAbs().maxCoeff(),
                                                              box.max.cwiseAbs().maxCoeff())) +
                       1e-30;
  tbb::parallel_for(Eigen::Index(0), C.rows(), [&](Eigen::Index f) {
    if (!counted(faces, f)) return;
    Query q;
    q.output = &output;
    q.faces = &scene_faces;
    q.c = C.row(f).transpose();
    q.n = N.row(f).transpose();
    q.below = below;
    q.radius = radius;
    RTCPointQuery pq;
    pq.x = static_cast<float>(q.c.x());
    pq.y = static_cast<float>(q.c.y());
    pq.z = static_cast<float>(q.c.z());
    pq.time = 0.0f;
    pq.radius = static_cast<float>(radius + slack + 1e-6 * q.c.cwiseAbs().maxCoeff());
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene, &pq, &context, visit, &q);
    covered[static_cast<size_t>(f)] = q.found;
  });
  return covered;
}

}  // namespace

double surface_coverage(const TriMesh& base, const TriMesh& output, double radius, double below,
                        const std::vector<char>& faces) {
  MQ_CHECK(base.F.rows() > 0, InvalidInput, "coverage: the base has no faces");
  MQ_CHECK(base.V.allFinite(), InvalidInput, "coverage: the base has non-finite vertices");
  MQ_CHECK(radius >= 0 && std::isfinite(radius), InvalidInput,
           "coverage: radius must be finite and >= 0, got ", radius);
  MQ_CHECK(below >= 0 && std::isfinite(below), InvalidInput,
           "coverage: below must be finite and >= 0, got ", below);
  MQ_CHECK(faces.empty() || static_cast<Eigen::Index>(faces.size()) == base.F.rows(), InvalidInput,
           "coverage: ", faces.size(), " mask flags for ", base.F.rows(), " faces");
  if (output.F.rows() == 0) return 0.0;
  MQ_CHECK(output.V.allFinite(), InvalidInput, "coverage: the output has non-finite vertices");
  MQ_CHECK(output.F.minCoeff() >= 0 && output.F.maxCoeff() < output.V.rows(), InvalidInput,
           "coverage: an output face index is out of range");
  // First by the output's vertices, then the faces left by the output's triangles.
  MatrixX3d C(base.F.rows(), 3);
  for (Eigen::Index f = 0; f < base.F.rows(); ++f)
    C.row(f) =
        (base.V.row(base.F(f, 0)) + base.V.row(base.F(f, 1)) + base.V.row(base.F(f, 2))) / 3.0;
  const MatrixX3d N = face_normals(base.V, base.F);
  std::vector<unsigned char> covered(static_cast<size_t>(base.F.rows()), 0);
  {
    const VertexGrid grid(output, radius);
    tbb::parallel_for(Eigen::Index(0), base.F.rows(), [&](Eigen::Index f) {
      if (counted(faces, f))
        covered[static_cast<size_t>(f)] =
            grid.covers(C.row(f).transpose(), N.row(f).transpose(), radius, below);
    });
  }
  std::vector<char> left(static_cast<size_t>(base.F.rows()), 0);
  std::vector<Eigen::Index> left_rows;
  for (Eigen::Index f = 0; f < base.F.rows(); ++f)
    if (counted(faces, f) && !covered[static_cast<size_t>(f)]) {
      left[static_cast<size_t>(f)] = 1;
      left_rows.push_back(f);
    }
  const std::vector<int> near = left_rows.empty()
                                    ? std::vector<int>()
                                    : triangles_near(output, C(left_rows, Eigen::all), radius);
  if (!near.empty()) {
    const EmbreeDevice device;
    const OutputScene scene(device, output, near);
    const std::vector<unsigned char> by_triangles =
        covered_faces(C, N, output, near, scene.get(), radius, below, left);
    for (size_t f = 0; f < covered.size(); ++f) covered[f] = covered[f] || by_triangles[f];
  }
  const Eigen::VectorXd A = face_areas(base.V, base.F);
  // Summed in face order so the result does not depend on the thread count.
  double sum = 0, total = 0;
  for (Eigen::Index f = 0; f < base.F.rows(); ++f) {
    if (!counted(faces, f)) continue;
    total += A(f);
    if (covered[static_cast<size_t>(f)]) sum += A(f);
  }
  return total > 0 ? sum / total : 0.0;
}

double swatch_coverage(const TriMesh& swatch) {
  const PreparedSwatch prepared = prepare_swatch(swatch);
  const int n = 48;
  TriMesh grid;
  grid.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      grid.V.row(j * (n + 1) + i) << prepared.size.x() * i / n, prepared.size.y() * j / n, 0.0;
  grid.F.resize(2 * n * n, 3);
  for (int j = 0, f = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      grid.F.row(f++) << a, b, d;  // counter-clockwise seen from +z, the swatch's side
      grid.F.row(f++) << a, d, c;
    }
  const double h = prepared.size.z();
  return surface_coverage(grid, prepared.mesh, 1.5 * h, 0.01 * h);
}

}  // namespace mq
