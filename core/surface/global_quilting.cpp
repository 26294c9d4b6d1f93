#include "core/surface/global_quilting.h"

#include <tbb/parallel_for.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/vertex_cover.h"
#include "core/mesh/weld_vertices.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/quilt_elements.h"
#include "core/planar/swatch_symmetry.h"
#include "core/surface/cone_placement.h"
#include "core/surface/global_parameterization.h"
#include "core/surface/line_field.h"
#include "core/surface/straightest_geodesic.h"
#include "core/surface/tangent_field.h"
#include "core/surface/thread_tiling.h"
#include "core/surface/trivial_connection.h"
#include "core/surface/vine_growth.h"

namespace mq {

namespace {

// The parameter-plane triangles binned in a uniform grid, for "which faces contain point p".
class ChartGrid {
 public:
  ChartGrid(const GlobalParameterization& gp, int num_faces) : gp_(gp) {
    lo_ = gp.wedge_uv.colwise().minCoeff().transpose();
    const Vector2d hi = gp.wedge_uv.colwise().maxCoeff().transpose();
    const double side = std::max((hi - lo_).maxCoeff(), 1e-12);
    const int n = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(num_faces))));
    cell_ = side / n;
    nx_ = std::max(1, static_cast<int>((hi.x() - lo_.x()) / cell_) + 1);
    ny_ = std::max(1, static_cast<int>((hi.y() - lo_.y()) / cell_) + 1);
    cells_.assign(static_cast<size_t>(nx_) * ny_, {});
    for (int f = 0; f < num_faces; ++f) {
      Vector2d a = gp.uv(f, 0), b = a;
      for (int k = 1; k < 3; ++k) {
        a = a.cwiseMin(gp.uv(f, k));
        b = b.cwiseMax(gp.uv(f, k));
      }
      for (int y = cy(a.y()); y <= cy(b.y()); ++y)
        for (int x = cx(a.x()); x <= cx(b.x()); ++x)
          cells_[static_cast<size_t>(y) * nx_ + x].push_back(f);
    }
  }
  // Faces whose triangle contains p (closed), ascending.
  std::vector<int> containing(const Vector2d& p) const {
    std::vector<int> out;
    for (const int f : cells_[static_cast<size_t>(cy(p.y())) * nx_ + cx(p.x())]) {
      const Vector2d a = gp_.uv(f, 0), b = gp_.uv(f, 1), c = gp_.uv(f, 2);
      const Vector2d e0 = b - a, e1 = c - a, d = p - a;
      const double den = e0.x() * e1.y() - e1.x() * e0.y();
      if (!(std::abs(den) > 0)) continue;
      const double v = (d.x() * e1.y() - e1.x() * d.y()) / den;
      const double w = (e0.x() * d.y() - d.x() * e0.y()) / den;
      if (v >= 0 && w >= 0 && v + w <= 1) out.push_back(f);
    }
    return out;
  }

 private:
  int cx(double x) const { return std::clamp(static_cast<int>((x - lo_.x()) / cell_), 0, nx_ - 1); }
  int cy(double y) const { return std::clamp(static_cast<int>((y - lo_.y()) / cell_), 0, ny_ - 1); }
  const GlobalParameterization& gp_;
  Vector2d lo_;
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
};

bool share_wedge(const GlobalParameterization& gp, int f, int g) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (gp.corner_wedge(f, i) == gp.corner_wedge(g, j)) return true;
  return false;
}

// The element with plane coordinates P (#V by 3: x, y in f0's chart, z the height) carried onto
// the base from face f0, vertex by vertex, each walk starting where the previous one ended.
// False when a vertex lies beyond a boundary or around a singular vertex. turn (optional)
// receives per vertex the sign of the chart transition from f0's chart to its face's (+1, or -1
// across a half turn). Heights are scaled by height_scale (a size map's nominal size: the
// element's width follows the layout, its thickness this).
bool place_from(const GlobalParameterization& gp, const SurfaceJob& job, const MatrixX3d& P, int f0,
                double shell_height, SurfaceElement& s, std::vector<signed char>* turn = nullptr,
                double height_scale = 1) {
  s.face.resize(P.rows());
  s.barycentric.resize(P.rows(), 3);
  s.height.resize(P.rows());
  int face = f0;
  ChartTransform to_current;  // from f0's chart to the walk's current face's
  for (Eigen::Index v = 0; v < P.rows(); ++v) {
    Vector2d x = to_current(P.row(v).head<2>().transpose());
    Vector3d b;
    if (!locate_in_charts(gp, job.topo, job.TT, job.base.F, face, x, b, 256, &to_current))
      return false;
    s.face[v] = face;
    s.barycentric.row(v) = b.transpose();
    s.height(v) = std::clamp(height_scale * P(v, 2), 0.0, shell_height);
    if (turn) turn->push_back(static_cast<signed char>(to_current.sigma));
  }
  s.flat = P;
  return true;
}

// The layout's differential on each face of the base: the 2 by 3 map taking a tangent vector
// of the face to the plane (plane units per surface unit), rows in the face's plane; zero where
// the face or its chart triangle is degenerate or flipped. #F by 6 (row 0, then row 1).
Eigen::MatrixXd layout_differential(const GlobalParameterization& gp, const TriMesh& base) {
  const FaceFrames fr = face_frames(base.V, base.F);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(base.num_faces(), 6);
  for (int f = 0; f < base.num_faces(); ++f) {
    const Vector3d x0 = base.V.row(base.F(f, 0)), x1 = base.V.row(base.F(f, 1)),
                   x2 = base.V.row(base.F(f, 2));
    const Vector3d b1 = fr.b1.row(f).transpose(), b2 = fr.b2.row(f).transpose();
    Eigen::Matrix2d E3, Q;
    E3 << (x1 - x0).dot(b1), (x2 - x0).dot(b1), (x1 - x0).dot(b2), (x2 - x0).dot(b2);
    Q.col(0) = gp.uv(f, 1) - gp.uv(f, 0);
    Q.col(1) = gp.uv(f, 2) - gp.uv(f, 0);
    if (!(std::abs(E3.determinant()) > 0)) continue;
    const Eigen::Matrix2d J = Q * E3.inverse();
    if (!(J.determinant() > 0)) continue;
    out.row(f).head<3>() = (J(0, 0) * b1 + J(0, 1) * b2).transpose();
    out.row(f).tail<3>() = (J(1, 0) * b1 + J(1, 1) * b2).transpose();
  }
  return out;
}

// Whether an element carried through the layout keeps the swatch element's shape: the
// layout's differential averaged over the faces its vertices lie on is nearly a similarity
// (singular values s1 / s2 at most max_element_aspect) not much larger than the texture (element
// scale 1 / sqrt(s1 s2) at most max_element_scale), and the same one
// across it (the scales of the element's two halves, split across its longest footprint axis,
// within max_element_variation of each other: no teardrop), each face's differential taken into
// the element's chart (turn: place_from's). Intrinsic: the surface's bending
// of the element is not distortion; averaged: the layout's per-triangle noise is not either.
// Smaller elements pass, at any variation and up to small_element_aspect: they lie where the
// layout gathers curvature (around + cones), are linked as densely as the lattice there, and an
// even copy of full size would collide.
bool within_shape_limits(const Eigen::MatrixXd& differential, const MatrixX3d& P,
                         const SurfaceElement& s, const std::vector<signed char>& turn,
                         const SurfaceQuiltingOptions::Global& options,
                         Eigen::Matrix<double, 2, 3>& mean, double nominal = 1) {
  if (s.face.empty()) return true;
  // The halves: either side of the centre along the footprint's x or y, whichever is longer.
  const Eigen::RowVector2d lo = P.leftCols<2>().colwise().minCoeff(),
                           hi = P.leftCols<2>().colwise().maxCoeff();
  const int axis = (hi - lo)(0) >= (hi - lo)(1) ? 0 : 1;
  const double mid = 0.5 * (lo(axis) + hi(axis));
  Eigen::Matrix<double, 2, 3> sum[2] = {Eigen::Matrix<double, 2, 3>::Zero(),
                                        Eigen::Matrix<double, 2, 3>::Zero()};
  int count[2] = {0, 0};
  for (size_t v = 0; v < s.face.size(); ++v) {
    // In the element's own chart: across a half-turn transition the differential is negated.
    const Eigen::RowVectorXd d = turn[v] * differential.row(s.face[v]);
    if (d.squaredNorm() == 0) return false;
    const int half = P(static_cast<Eigen::Index>(v), axis) < mid ? 0 : 1;
    sum[half].row(0) += d.head<3>();
    sum[half].row(1) += d.tail<3>();
    ++count[half];
  }
  auto scale_of = [](const Eigen::Matrix<double, 2, 3>& m, double* aspect) {
    const Eigen::JacobiSVD<Eigen::Matrix<double, 2, 3>> svd(m);
    const double s1 = svd.singularValues()(0), s2 = svd.singularValues()(1);
    if (aspect) *aspect = s2 > 0 ? s1 / s2 : std::numeric_limits<double>::infinity();
    return std::sqrt(s1 * s2);
  };
  double aspect = 1;
  mean = (sum[0] + sum[1]) / static_cast<double>(count[0] + count[1]);
  const double all = scale_of(mean, &aspect);
  if (!(all > 0)) return false;
  const double element_scale = 1 / all;
  bool even = true;
  if (count[0] > 0 && count[1] > 0) {
    const double a = scale_of(sum[0] / count[0], nullptr), b = scale_of(sum[1] / count[1], nullptr);
    even = std::max(a, b) <= options.max_element_variation * std::min(a, b);
  }
  if (element_scale / nominal < options.small_element_scale &&
      aspect <= options.small_element_aspect)
    return true;  // around a positive cone (SurfaceQuiltingOptions::Global::small_element_scale)
  return element_scale / nominal <= options.max_element_scale &&
         aspect <= options.max_element_aspect && even;
}

// The element as the layout's first-order image at its centre, bent only by the surface: its
// centre is located through the layout, and every vertex's offset from the centre, taken
// through the inverse of the layout's differential M (2 by 3, plane per surface unit), is walked
// along the surface as a straightest geodesic. Where M is far from a similarity (aspect over
// max_element_aspect) only its rotation and mean scale are kept; the scale makes the element
// 1 / sqrt(s1 s2) times the swatch's, clamped to [1 / max_element_scale, max_element_scale]
// times the nominal size (a size map's, else 1; within_shape_limits' scale is against it too). So
// an element keeps its place among neighbours laid out through the layout to first order (its
// links), and loses only the layout's variation across it (a teardrop's) and extreme sizes.
bool place_linear(const GlobalParameterization& gp, const SurfaceJob& job,
                  const Eigen::Matrix<double, 2, 3>& M, const MatrixX3d& P, const Vector2d& centre,
                  int f, double shell_height, bool similarity,
                  const SurfaceQuiltingOptions::Global& options, SurfaceElement& s,
                  double nominal = 1) {
  const MatrixX3i& F = job.base.F;
  // Thin V needs a dynamic column count (Eigen asserts it; a fixed 2 x 3 is refused).
  const Eigen::JacobiSVD<Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, 3>> svd(
      M, Eigen::ComputeFullU | Eigen::ComputeThinV);
  Vector2d sv = svd.singularValues();
  if (!(sv(1) > 0)) return false;
  const double sigma = std::sqrt(sv(0) * sv(1));
  if (similarity || sv(0) > options.max_element_aspect * sv(1)) sv.setConstant(sigma);
  const double k = std::clamp(1.0 / sigma, nominal / options.max_element_scale,
                              nominal * options.max_element_scale);
  // Plane offset -> surface offset: V diag(1 / sv) U^T, rescaled to the clamped size.
  const Eigen::Matrix<double, 3, 2> inverse =
      (k * sigma) * svd.matrixV() * sv.cwiseInverse().asDiagonal() * svd.matrixU().transpose();
  // The centre's barycentric coordinates in f's chart triangle.
  const Vector2d u0 = gp.uv(f, 0);
  Eigen::Matrix2d Q;
  Q.col(0) = gp.uv(f, 1) - u0;
  Q.col(1) = gp.uv(f, 2) - u0;
  if (!(std::abs(Q.determinant()) > 0)) return false;
  const Vector2d w = Q.inverse() * (centre - u0);
  Vector3d bc(1 - w.x() - w.y(), w.x(), w.y());
  bc = bc.cwiseMax(0.0);
  bc /= bc.sum();
  s.face.resize(P.rows());
  s.barycentric.resize(P.rows(), 3);
  s.height.resize(P.rows());
  for (Eigen::Index v = 0; v < P.rows(); ++v) {
    const Vector3d offset = inverse * (P.row(v).head<2>().transpose() - centre);
    int face = f;
    Vector3d b = bc;
    if (!straightest_walk(job.base.V, F, job.TT, face, b, offset)) return false;
    s.face[v] = face;
    s.barycentric.row(v) = b.transpose();
    // A copy made smaller keeps its proportions; a larger one keeps its height (the shell's).
    s.height(v) = std::clamp(std::min(k, 1.0) * P(v, 2), 0.0, shell_height);
  }
  // The flat shape the fold repair falls back to: the copy at the size it was placed at.
  s.flat = P;
  for (Eigen::Index v = 0; v < P.rows(); ++v)
    s.flat.row(v).head<2>() = (centre + k * (P.row(v).head<2>().transpose() - centre)).transpose();
  return true;
}

// One lattice copy of an orbit representative whose centre lies in a chart triangle.
struct LatticeCopy {
  int rep = 0;                                  // index into the representatives
  Eigen::Vector2i k = Eigen::Vector2i::Zero();  // lattice coordinates of its translation
  int face = 0;                                 // a base face whose chart triangle holds its centre
  bool operator<(const LatticeCopy& o) const {
    if (rep != o.rep) return rep < o.rep;
    if (k.y() != o.k.y()) return k.y() < o.k.y();
    if (k.x() != o.k.x()) return k.x() < o.k.x();
    return face < o.face;
  }
};

// Every copy of every representative (centre c_r + lattice, in plane coordinates) that lies in
// the chart triangle of some face, one per place on the surface: faces of one chart around a
// centre on their common edge or vertex are the same place. Only the lattice points over the
// triangles are visited, so the work and memory follow the surface's parameter area, not the
// box around the charts (Blender's UV sphere, whose charts spread over a plane 60 times their
// area, ran out of memory when the box was tiled). Sorted by representative, then lattice row
// and column: deterministic.
std::vector<LatticeCopy> lattice_copies(const GlobalParameterization& gp, int num_faces,
                                        const SwatchSymmetry& sym,
                                        const std::vector<Vector2d>& centres) {
  Eigen::Matrix2d basis;
  basis.col(0) = sym.a;
  basis.col(1) = sym.b;
  const Eigen::Matrix2d inv = basis.inverse();
  std::vector<std::vector<LatticeCopy>> per(static_cast<size_t>(num_faces));
  tbb::parallel_for(0, num_faces, [&](int f) {
    const Vector2d a = gp.uv(f, 0), b = gp.uv(f, 1), c = gp.uv(f, 2);
    const Vector2d e0 = b - a, e1 = c - a;
    const double den = e0.x() * e1.y() - e1.x() * e0.y();
    if (!(std::abs(den) > 0)) return;
    for (size_t r = 0; r < centres.size(); ++r) {
      Vector2d kmin = Vector2d::Constant(std::numeric_limits<double>::infinity()), kmax = -kmin;
      for (const Vector2d& q : {a, b, c}) {
        const Vector2d k = inv * (q - centres[r]);
        kmin = kmin.cwiseMin(k);
        kmax = kmax.cwiseMax(k);
      }
      for (long j = static_cast<long>(std::ceil(kmin.y() - 1e-9));
           j <= static_cast<long>(std::floor(kmax.y() + 1e-9)); ++j)
        for (long i = static_cast<long>(std::ceil(kmin.x() - 1e-9));
             i <= static_cast<long>(std::floor(kmax.x() + 1e-9)); ++i) {
          const Vector2d d =
              centres[r] + basis * Vector2d(static_cast<double>(i), static_cast<double>(j)) - a;
          const double v = (d.x() * e1.y() - e1.x() * d.y()) / den;
          const double w = (e0.x() * d.y() - d.x() * e0.y()) / den;
          if (v >= 0 && w >= 0 && v + w <= 1)
            per[static_cast<size_t>(f)].push_back(
                {static_cast<int>(r), Eigen::Vector2i(static_cast<int>(i), static_cast<int>(j)),
                 f});
        }
    }
  });
  std::vector<LatticeCopy> all;
  for (auto& p : per) all.insert(all.end(), p.begin(), p.end());
  std::sort(all.begin(), all.end());
  // One per place: a copy found in several faces of one chart that share a corner group.
  std::vector<LatticeCopy> out;
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j].rep == all[i].rep && all[j].k == all[i].k) ++j;
    const size_t first = out.size();
    for (size_t q = i; q < j; ++q) {
      bool same = false;
      for (size_t o = first; o < out.size() && !same; ++o)
        same = share_wedge(gp, all[q].face, out[o].face);
      if (!same) out.push_back(all[q]);
    }
    i = j;
  }
  return out;
}

}  // namespace

namespace {

// One implicit step of the uniform Laplacian, x' = (I + w L)^-1 x, then scaled back to the
// base's area about the centroid (the step shrinks): detail of about an edge's size is gone.
MatrixX3d smoothed_positions(const TriMesh& base, const EdgeTopology& topo, double weight) {
  const int nv = base.num_vertices();
  std::vector<Eigen::Triplet<double>> t;
  std::vector<double> degree(static_cast<size_t>(nv), 0);
  for (int e = 0; e < topo.num_edges(); ++e) {
    const int a = topo.E(e, 0), b = topo.E(e, 1);
    t.emplace_back(a, b, -weight);
    t.emplace_back(b, a, -weight);
    degree[a] += weight;
    degree[b] += weight;
  }
  for (int v = 0; v < nv; ++v) t.emplace_back(v, v, 1.0 + degree[v]);
  Eigen::SparseMatrix<double> M(nv, nv);
  M.setFromTriplets(t.begin(), t.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
  MQ_CHECK(ldlt.info() == Eigen::Success, SolverFailure,
           "global parameterisation: the smoothing system could not be factorised");
  const Eigen::MatrixXd X = base.V;
  MatrixX3d S = ldlt.solve(X);
  const double a0 = surface_area(base.V, base.F), a1 = surface_area(S, base.F);
  if (!(a1 > 0) || !S.allFinite()) return base.V;
  const double k = std::sqrt(a0 / a1);
  const Vector3d c0 = S.colwise().mean().transpose(), c1 = base.V.colwise().mean().transpose();
  for (Eigen::Index v = 0; v < S.rows(); ++v)
    S.row(v) = (c1 + k * (S.row(v).transpose() - c0)).transpose();
  return S;
}

// Median over faces (by area) of the linear scale sqrt(area in the plane / area on the base).
double median_scale(const GlobalParameterization& gp, const TriMesh& base) {
  std::vector<std::pair<double, double>> s;  // (scale, area)
  double total = 0;
  for (int f = 0; f < base.num_faces(); ++f) {
    const Vector2d a = gp.uv(f, 0), b = gp.uv(f, 1), c = gp.uv(f, 2);
    const double ap = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    const Vector3d p0 = base.V.row(base.F(f, 0)), p1 = base.V.row(base.F(f, 1)),
                   p2 = base.V.row(base.F(f, 2));
    const double a3 = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    if (!(a3 > 0)) continue;
    s.emplace_back(std::sqrt(ap / a3), a3);
    total += a3;
  }
  if (s.empty()) return 1;
  std::sort(s.begin(), s.end());
  double acc = 0;
  for (const auto& [scale, area] : s) {
    acc += area;
    if (acc >= 0.5 * total) return scale > 0 ? scale : 1;
  }
  return 1;
}

// The geometric mean over the base (area-weighted) of the layout's linear scale
// sqrt(area in the plane / area on the base): the scale at which the conformal layout's log
// scale u has mean zero, as the metric's own (core/surface/trivial_connection). Its scale varies
// (e^u) with a long tail around + cones, where elements gather: normalised at its median over
// the surface, the density was 107-113% and the median element 0.92x the swatch's (Spot,
// spheres); by the areas' ratio (density 100% in the layout), 85-91% and 0.98-1.08x.
double log_mean_scale(const GlobalParameterization& gp, const TriMesh& base) {
  double sum = 0, total = 0;
  for (int f = 0; f < base.num_faces(); ++f) {
    const Vector2d a = gp.uv(f, 0), b = gp.uv(f, 1), c = gp.uv(f, 2);
    const double ap = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    const Vector3d p0 = base.V.row(base.F(f, 0)), p1 = base.V.row(base.F(f, 1)),
                   p2 = base.V.row(base.F(f, 2));
    const double a3 = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    if (!(a3 > 0) || !(ap > 0)) continue;
    sum += a3 * 0.5 * std::log(ap / a3);
    total += a3;
  }
  return total > 0 ? std::exp(sum / total) : 1.0;
}

// The area-weighted mean over job.base of log nominal_size.
double mean_log_size(const SurfaceJob& job) {
  const Eigen::VectorXd area = face_areas(job.base.V, job.base.F);
  double sum = 0;
  for (int f = 0; f < job.base.num_faces(); ++f) sum += area(f) * face_log_size(job, f);
  return area.sum() > 0 ? sum / area.sum() : 0.0;
}

// Nearest point of offset + lattice(a, b) to x.
Vector2d nearest_symmetry(const SwatchSymmetry& sym, const Vector2d& x, const Vector2d& offset) {
  Eigen::Matrix2d basis;
  basis.col(0) = sym.a;
  basis.col(1) = sym.b;
  const Vector2d k = basis.inverse() * (x - offset);
  return offset + basis * Vector2d(std::round(k.x()), std::round(k.y()));
}

// The parameterisation, made seamless for a texture with the given symmetries: solved once,
// scaled so that its median scale is 1 (texture at its nominal size on most of the base); then
// the half-turn cones pinned to the texture's half-turn centres ((c + lattice) / 2 in the plane
// quilt's coordinates, which start at `anchor`), which makes every transition around them a
// symmetry of the texture; then the translation of every cut path (a handle, a path between
// boundaries, or one still off after the pins) fixed at the nearest symmetry. Each stage is one
// more solve of the same size.
GlobalParameterization seamless_parameterization(const MatrixX3d& V, const TriMesh& base,
                                                 const SurfaceJob& job, const DirectionField& df,
                                                 const Eigen::VectorXd& face_scale,
                                                 const SwatchSymmetry& sym, bool seamless,
                                                 Vector2d& anchor, GlobalQuiltingStats& stats) {
  GlobalParameterizationOptions go;
  go.face_scale = face_scale;
  GlobalParameterization gp = global_parameterization(V, base.F, job.topo, job.TT, df, go);
  double sigma = face_scale.size() ? log_mean_scale(gp, base) : median_scale(gp, base);
  // A size map's mean (relative to the swatch, at the largest size) is kept, not normalised.
  if (job.log_size.size()) sigma *= std::exp(mean_log_size(job));
  gp.wedge_uv /= sigma;
  go.target_scale = 1.0 / sigma;
  stats.scale_correction = 1.0 / sigma;
  anchor = gp.wedge_uv.colwise().minCoeff().transpose();
  if (!seamless || !sym.periodic || !sym.half_turn) return gp;
  // On a closed component the transitions around all its cones compose to the identity, so
  // the cones' places are not independent: each pinned to its nearest half-turn centre, the
  // product of their half turns is in general a lattice translation, not the identity, and the
  // soft pins then share that period out between them (knight: every pin 0.026 periods off,
  // transitions up to 1.1 periods off a symmetry). Pinned all but one, the last is
  // where the others put it: a half-turn centre too, since a product of half turns about
  // half-turn centres is a symmetry. The one left free is the cone its pin would move most.
  std::vector<int> face_component;
  const int components = connected_components(base.F, base.num_vertices(), face_component);
  std::vector<char> closed(static_cast<size_t>(components), 1);
  for (int e = 0; e < job.topo.num_edges(); ++e)
    if (job.topo.edge_faces.degree(e) != 2 && job.topo.edge_faces.degree(e) > 0)
      closed[face_component[job.topo.edge_faces.begin(e)[0]]] = 0;
  std::vector<int> free_pin(static_cast<size_t>(components), -1);
  std::vector<double> free_shift(static_cast<size_t>(components), -1);
  std::vector<char> pinned(static_cast<size_t>(base.num_vertices()), 0);
  for (int f = 0; f < base.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = base.F(f, k);
      if (pinned[v] || df.index[v] % 2 == 0) continue;
      pinned[v] = 1;
      const Vector2d x = gp.uv(f, k) - anchor;
      const Vector2d at = anchor + 0.5 * nearest_symmetry(sym, 2 * x, sym.c);
      const int c = face_component[static_cast<size_t>(f)];
      const double shift = (at - gp.uv(f, k)).norm();
      if (closed[c] && shift > free_shift[c]) {
        free_shift[c] = shift;
        free_pin[c] = static_cast<int>(go.pinned.size());
      }
      go.pinned.emplace_back(v, at);
    }
  {
    std::vector<char> keep(go.pinned.size(), 1);
    for (const int i : free_pin)
      if (i >= 0) keep[static_cast<size_t>(i)] = 0;
    std::vector<std::pair<int, Vector2d>> kept;
    for (size_t i = 0; i < go.pinned.size(); ++i)
      if (keep[i]) kept.push_back(go.pinned[i]);
    go.pinned = std::move(kept);
  }
  stats.pinned_cones = static_cast<int>(go.pinned.size());
  gp = global_parameterization(V, base.F, job.topo, job.TT, df, go);
  // In plane coordinates a transition uv_g = s uv_f + t has translation t + (s - 1) anchor.
  auto target = [&](const CutPath& path, const Vector2d& t) {
    const Vector2d tp = t + (path.sign - 1) * anchor;
    return nearest_symmetry(sym, tp, path.sign > 0 ? Vector2d::Zero() : sym.c);
  };
  for (const CutPath& path : cut_paths(gp, job.topo, base.F)) {
    const Vector2d rounded =
        target(path, path_translation(gp, job.topo, base.F, path)) - (path.sign - 1) * anchor;
    for (size_t k = 0; k < path.edges.size(); ++k)
      go.fixed_translation.emplace_back(path.edges[k], edge_translation(path, k, rounded));
  }
  gp = global_parameterization(V, base.F, job.topo, job.TT, df, go);
  stats.seamless = true;
  // How far the transitions stayed from the texture's symmetries (the constraints are soft).
  const double period = std::min(sym.a.norm(), sym.b.norm());
  for (const CutPath& path : cut_paths(gp, job.topo, base.F)) {
    ++stats.cut_paths;
    const Vector2d t = path_translation(gp, job.topo, base.F, path) + (path.sign - 1) * anchor;
    stats.worst_transition_error =
        std::max(stats.worst_transition_error,
                 (t - target(path, t - (path.sign - 1) * anchor)).norm() / period);
  }
  return gp;
}

}  // namespace

namespace {

// The parameter plane's area over the base's faces, added to `area`.
void add_parameter_area(const GlobalParameterization& gp, int num_faces, double& area) {
  for (int f = 0; f < num_faces; ++f) {
    const Vector2d a = gp.uv(f, 0), b = gp.uv(f, 1), c = gp.uv(f, 2);
    area += 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  }
}

// The copies of the lattice over the parameterised surface: the orbit representatives (indices
// into the swatch's elements), their centres in the plane and every copy, counted in faces
// before anything is built (section 2's quilt of such a swatch is its lattice tiling).
struct LatticeTiling {
  std::vector<int> reps;
  std::vector<Vector2d> centres;
  std::vector<LatticeCopy> copies;
};

// The tiling, its size in gstats; refused over options.max_faces. Empty when the job only counts.
LatticeTiling tile_lattice(const GlobalParameterization& gp, const SurfaceJob& job,
                           const PreparedSwatch& swatch, const PreparedSwatch& full,
                           const SwatchSymmetry& sym, const Vector2d& lo,
                           const SurfaceQuiltingOptions& options, GlobalQuiltingStats& gstats) {
  const double max_faces = options.max_faces;
  LatticeTiling t;
  // The orbits and their centres at full detail: a Preview places the same copies.
  t.reps = orbit_representatives(full, sym);
  gstats.orbits = static_cast<int>(t.reps.size());
  for (const int r : t.reps) t.centres.push_back(element_centre(full.elements[r]) + lo);
  t.copies = lattice_copies(gp, job.base.num_faces(), sym, t.centres);
  double faces = 0;
  for (const LatticeCopy& c : t.copies)
    faces += static_cast<double>(swatch.elements[t.reps[c.rep]].F.rows());
  gstats.layout_faces = faces;
  if (options.global.count_only) return {};
  MQ_CHECK(faces <= max_faces, InvalidInput, "the global layout would place ", t.copies.size(),
           " elements of about ", faces, " faces in all, more than the limit of ", max_faces,
           " (--max-faces, or --max-memory at 400 bytes a face); use a larger --scale");
  add_parameter_area(gp, job.base.num_faces(), gstats.parameter_area);
  return t;
}

// One copy P (the swatch element moved to its lattice place, centre `centre`, in face f's
// chart) placed on the base as options.placement says: through the layout where the layout
// keeps the element's shape (adaptive), else as a copy bent only by the surface (place_linear),
// which sets `copied`. False when it cannot be placed on the surface.
bool place_lattice_copy(const GlobalParameterization& gp, const SurfaceJob& job, const MatrixX3d& P,
                        const Vector2d& centre, int f, const Eigen::MatrixXd& differential,
                        double shell_height, const SurfaceQuiltingOptions::Global& options,
                        SurfaceElement& s, bool& copied) {
  using Placement = SurfaceQuiltingOptions::Global::Placement;
  const Placement mode = options.placement;
  // The layout's differential at the centre's face, or averaged over the element.
  Eigen::Matrix<double, 2, 3> M;
  M.row(0) = differential.row(f).head<3>();
  M.row(1) = differential.row(f).tail<3>();
  bool placed_ok = false, through_layout = false;
  // The size the size map asks for here (1 without one): the limits are taken against it.
  const double nominal = nominal_size(job, f);
  if (mode != Placement::kRigid) {
    std::vector<signed char> turn;
    placed_ok = through_layout = place_from(gp, job, P, f, shell_height, s, &turn, nominal);
    if (placed_ok && mode == Placement::kAdaptive &&
        !within_shape_limits(differential, P, s, turn, options, M, nominal))
      placed_ok = false;
  }
  copied = false;
  if (!placed_ok && mode != Placement::kLayout) {
    SurfaceElement::Alternative layout_version;
    if (through_layout)
      layout_version = {std::move(s.face), std::move(s.barycentric), std::move(s.height)};
    placed_ok = place_linear(gp, job, M, P, centre, f, shell_height, mode == Placement::kRigid,
                             options, s, nominal);
    if (placed_ok) s.through_layout = std::move(layout_version);
    copied = placed_ok;
  }
  return placed_ok;
}

// The lattice of a tileable swatch carried onto the base: every copy whose centre lies on the
// parameterised surface, placed from the face holding its centre. The output is counted before
// anything is built, and refused over max_faces.
std::vector<SurfaceElement> place_lattice(const GlobalParameterization& gp, const SurfaceJob& job,
                                          const PreparedSwatch& swatch, const PreparedSwatch& full,
                                          const SwatchSymmetry& sym, const Vector2d& lo,
                                          const SurfaceQuiltingOptions& options,
                                          GlobalQuiltingStats& gstats, StageTimes& times,
                                          ProgressSink* progress) {
  LatticeTiling tiling;
  {
    ScopedStage stage(times, progress, Stage::Tiling);
    tiling = tile_lattice(gp, job, swatch, full, sym, lo, options, gstats);
    if (options.global.count_only) return {};
  }
  const std::vector<LatticeCopy>& copies = tiling.copies;
  ScopedStage stage(times, progress, Stage::Placement);
  Eigen::Matrix2d basis;
  basis.col(0) = sym.a;
  basis.col(1) = sym.b;
  const Eigen::MatrixXd differential = layout_differential(gp, job.base);
  const int n = static_cast<int>(copies.size());
  std::vector<SurfaceElement> out(copies.size());
  std::vector<char> ok(copies.size(), 0), copied(copies.size(), 0);
  // In blocks, so that progress is reported from this thread between them (each copy's
  // placement depends only on it: the result is the same whatever the blocks).
  const int block = std::max(64, n / 50);
  for (int first = 0; first < n; first += block) {
    report_progress(progress, Stage::Placement, first, n);
    tbb::parallel_for(first, std::min(n, first + block), [&](int i) {
      const LatticeCopy& c = copies[static_cast<size_t>(i)];
      const Element& e = swatch.elements[static_cast<size_t>(tiling.reps[c.rep])];
      const Vector2d t = lo + basis * c.k.cast<double>();
      MatrixX3d P = e.V;
      P.col(0).array() += t.x();
      P.col(1).array() += t.y();
      SurfaceElement& s = out[static_cast<size_t>(i)];
      s.F = e.F;
      s.kind = e.kind;
      const Vector2d centre =
          tiling.centres[static_cast<size_t>(c.rep)] + basis * c.k.cast<double>();
      bool by_copy = false;
      ok[static_cast<size_t>(i)] = place_lattice_copy(gp, job, P, centre, c.face, differential,
                                                      swatch.size.z(), options.global, s, by_copy);
      copied[static_cast<size_t>(i)] = by_copy;
      // A copy of the swatch element vertex for vertex: each vertex's source is its own place
      // there (issue 25, swatch animation).
      if (options.keep_sources) {
        s.source_element.assign(static_cast<size_t>(e.V.rows()), tiling.reps[c.rep]);
        s.source = e.V;
      }
    });
  }
  std::vector<SurfaceElement> placed;
  placed.reserve(copies.size());
  for (size_t i = 0; i < copies.size(); ++i) {
    if (ok[i])
      placed.push_back(std::move(out[i]));
    else
      ++gstats.off_surface;
    gstats.copied_elements += copied[i];
  }
  return placed;
}

// A quilted plane texture (a swatch that is not a lattice of separate elements) carried onto
// the base: every element from each face whose chart contains its centre. sources (optional):
// the plane's (quilt_plane), kept per element (SurfaceElement::source).
std::vector<SurfaceElement> place_plane(const GlobalParameterization& gp, const SurfaceJob& job,
                                        const TriMesh& plane, const PlaneSources* sources,
                                        double shell_height, GlobalQuiltingStats& gstats,
                                        StageTimes& times, ProgressSink* progress) {
  ScopedStage stage(times, progress, Stage::Placement);
  const ChartGrid grid(gp, job.base.num_faces());
  std::vector<int> fc;
  const int n = connected_components(plane.F, plane.num_vertices(), fc);
  const std::vector<std::vector<int>> groups = component_faces(fc, n);
  std::vector<std::vector<SurfaceElement>> per(static_cast<size_t>(n));
  std::vector<int> off(static_cast<size_t>(n), 0);
  const int block = std::max(64, n / 50);
  for (int first = 0; first < n; first += block) {
    report_progress(progress, Stage::Placement, first, n);
    tbb::parallel_for(first, std::min(n, first + block), [&](int c) {
      std::vector<int> vertices;
      const TriMesh part = extract_faces(plane, groups[c], &vertices);
      const Vector2d centre = part.V.leftCols<2>().colwise().mean().transpose();
      // One placement per place on the surface: faces of one chart around the centre (it lies
      // on their common edge or vertex) are the same place.
      std::vector<int> starts;
      for (const int f : grid.containing(centre)) {
        bool same = false;
        for (const int g : starts) same = same || share_wedge(gp, f, g);
        if (!same) starts.push_back(f);
      }
      for (const int f0 : starts) {
        SurfaceElement s;
        s.F = part.F;
        s.kind = has_kinds(plane) ? plane.face_kind[static_cast<size_t>(groups[c][0])] : 0;
        if (sources) {
          s.source.resize(part.num_vertices(), 3);
          for (size_t v = 0; v < vertices.size(); ++v) {
            s.source.row(static_cast<Eigen::Index>(v)) = sources->point.row(vertices[v]);
            s.source_element.push_back(sources->element[static_cast<size_t>(vertices[v])]);
          }
        }
        if (place_from(gp, job, part.V, f0, shell_height, s, nullptr, nominal_size(job, f0)))
          per[c].push_back(std::move(s));
        else
          ++off[c];
      }
    });
  }
  std::vector<SurfaceElement> placed;
  for (int c = 0; c < n; ++c) {
    gstats.off_surface += off[c];
    for (SurfaceElement& s : per[c]) placed.push_back(std::move(s));
  }
  return placed;
}

// How far the layout may bend a thread piece out of the swatch's shape (within_shape_limits'
// scale, aspect and variation) before it is left out. Looser than for rings, which have a copy
// to fall back to (place_linear): a left-out piece ends two threads and bares the surface.
// Measured on the cup at 1.3 / 1.6 / 2.5: coverage 0.897 / 0.979 / 0.992 (the handle's side,
// where the layout gathers its cones, bare at 1.3); at 2.5 threads there are visibly thickened.
constexpr double kThreadShapeLimit = 1.6;

// The share of the thread pieces on the surface that the layout must keep (not bent out of shape,
// not next to a cone) for auto to take it; below it the patches quilt the job.
constexpr double kMinThreadPiecesKept = 0.5;

// Whether the layout carries the thread pieces (kMinThreadPiecesKept of those on the surface
// kept): a layout that bends or breaks most pieces carries no threads that run on, even when its
// area is even (the wicker chair's 77 rough parts, 471 cones: 28% of the pieces on the surface
// kept, coverage 48%; bunny 88%, cup 93%).
bool layout_carries_threads(const GlobalQuiltingStats& gstats) {
  const int on_surface = gstats.thread_pieces + gstats.pieces_distorted + gstats.pieces_near_cones;
  return gstats.thread_pieces >= kMinThreadPiecesKept * on_surface;
}

// A thread of one piece, cut off on both sides (next to a cone, between pieces left out), is a
// stub of one period, debris rather than a thread: left out (bunny: 6 of 151 threads).
constexpr int kMinThreadPieces = 2;

// Whether the layout can carry a tiling: the charts' area in the plane is at most 4 times the
// surface's, and the faces whose layout scales area within [1/4, 4] hold 80% of it. A layout
// that collapses and blows up faces (on the wicker chair's 77 parts: 1% of faces 140,000 times
// too large, 10% 250 times too small) would ask for millions of copies and leave parts bare.
bool layout_fit_for_tiling(const GlobalParameterization& gp, const TriMesh& base) {
  double plane = 0, surface = 0, even = 0;
  for (int f = 0; f < base.num_faces(); ++f) {
    const Vector2d a = gp.uv(f, 0), b = gp.uv(f, 1), c = gp.uv(f, 2);
    const double ap = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    const Vector3d p0 = base.V.row(base.F(f, 0)), p1 = base.V.row(base.F(f, 1)),
                   p2 = base.V.row(base.F(f, 2));
    const double a3 = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    plane += ap;
    surface += a3;
    if (ap >= 0.25 * a3 && ap <= 4 * a3) even += a3;
  }
  return surface > 0 && plane <= 4 * surface && even >= 0.8 * surface;
}

// Every lattice copy of every thread piece whose centre lies on the parameterised surface
// (lattice_copies), counted before anything is built and refused over options.max_faces.
std::vector<LatticeCopy> thread_piece_copies(const GlobalParameterization& gp,
                                             const SurfaceJob& job, const ThreadTiling& tiling,
                                             const SwatchSymmetry& sym, const Vector2d& lo,
                                             const SurfaceQuiltingOptions& options,
                                             GlobalQuiltingStats& gstats) {
  std::vector<Vector2d> centres;
  for (const ThreadPiece& p : tiling.pieces) centres.push_back(p.centre + lo);
  std::vector<LatticeCopy> copies = lattice_copies(gp, job.base.num_faces(), sym, centres);
  double faces = 0;
  for (const LatticeCopy& c : copies)
    faces += static_cast<double>(tiling.pieces[static_cast<size_t>(c.rep)].F.rows());
  MQ_CHECK(faces <= options.max_faces, InvalidInput, "the global layout would place ",
           copies.size(), " thread pieces of about ", faces,
           " faces in all, more than the limit of ", options.max_faces,
           " (--max-faces); use a larger --scale");
  add_parameter_area(gp, job.base.num_faces(), gstats.parameter_area);
  return copies;
}

// #singular vertices by 3: where the layout's cones are on the base.
MatrixX3d cone_positions(const GlobalParameterization& gp, const TriMesh& base) {
  MatrixX3d cones(gp.num_singular, 3);
  for (Eigen::Index v = 0, i = 0; v < base.V.rows(); ++v)
    if (gp.singular[static_cast<size_t>(v)]) cones.row(i++) = base.V.row(v);
  return cones;
}

// Why a lattice copy of a thread piece is left out, if it is (place_threads).
enum ThreadPieceOutcome : char { kPiecePlaced, kPieceOff, kPieceDistorted, kPieceNearCone };

// Lattice copies of thread pieces carried onto the base through the layout, vertex by vertex
// like place_lattice's elements, each checked against the shape limits and the cones.
class ThreadPiecePlacer {
 public:
  ThreadPiecePlacer(const GlobalParameterization& gp, const SurfaceJob& job,
                    const ThreadTiling& tiling, const SwatchSymmetry& sym, const Vector2d& lo,
                    double shell_height, const SurfaceQuiltingOptions::Global& options,
                    const MatrixX3d& N)
      : gp_(gp),
        job_(job),
        tiling_(tiling),
        lo_(lo),
        shell_height_(shell_height),
        N_(N),
        differential_(layout_differential(gp, job.base)),
        cones_(cone_positions(gp, job.base)),
        limits_(options) {
    basis_.col(0) = sym.a;
    basis_.col(1) = sym.b;
    limits_.max_element_scale = limits_.max_element_aspect = limits_.max_element_variation =
        kThreadShapeLimit;
    limits_.small_element_scale = 0;  // a thread piece bends with its neighbours or is left out
  }

  // Copy c placed into pp, its vertices embedded by normal displacement into X when it is kept.
  ThreadPieceOutcome place(const LatticeCopy& c, PlacedPiece& pp, MatrixX3d& X) const {
    const ThreadPiece& piece = tiling_.pieces[static_cast<size_t>(c.rep)];
    const Vector2d t = lo_ + basis_ * c.k.cast<double>();
    MatrixX3d P = piece.V;
    P.col(0).array() += t.x();
    P.col(1).array() += t.y();
    pp.piece = c.rep;
    SurfaceElement& s = pp.element;
    s.F = piece.F;
    s.kind = piece.kind;
    std::vector<signed char> turn;
    const double nominal = nominal_size(job_, c.face);
    if (!place_from(gp_, job_, P, c.face, shell_height_, s, &turn, nominal)) return kPieceOff;
    s.flat.resize(0, 3);  // a thread has no rigid shape to fall back to
    Eigen::Matrix<double, 2, 3> M;
    if (!within_shape_limits(differential_, P, s, turn, limits_, M, nominal))
      return kPieceDistorted;
    X.resize(P.rows(), 3);
    for (Eigen::Index v = 0; v < P.rows(); ++v)
      X.row(v) = displace_along_normal(job_.base, N_, s.face[static_cast<size_t>(v)],
                                       s.barycentric.row(v).transpose(), s.height(v))
                     .transpose();
    // One thread spacing: the distance between a thread and its next copy alongside.
    const double clearance = std::abs(basis_.determinant()) / piece.period.norm();
    for (Eigen::Index c = 0; c < cones_.rows(); ++c)
      if (((X.rowwise() - cones_.row(c)).rowwise().norm().array() < clearance).any())
        return kPieceNearCone;
    return kPiecePlaced;
  }

 private:
  const GlobalParameterization& gp_;
  const SurfaceJob& job_;
  const ThreadTiling& tiling_;
  const Vector2d lo_;
  const double shell_height_;
  const MatrixX3d& N_;
  const Eigen::MatrixXd differential_;
  Eigen::Matrix2d basis_;
  const MatrixX3d cones_;  // cone_positions
  SurfaceQuiltingOptions::Global limits_;
};

// The copies placed (ThreadPiecePlacer), in parallel in blocks so that progress is reported from
// this thread between them; those kept, in order, with their vertices embedded by normal
// displacement (*positions), the others counted in gstats.
std::vector<PlacedPiece> place_thread_copies(const ThreadPiecePlacer& placer,
                                             const std::vector<LatticeCopy>& copies,
                                             std::vector<MatrixX3d>* positions,
                                             GlobalQuiltingStats& gstats, ProgressSink* progress) {
  const int n = static_cast<int>(copies.size());
  std::vector<PlacedPiece> out(copies.size());
  std::vector<MatrixX3d> proxy(copies.size());
  std::vector<char> outcome(copies.size(), kPieceOff);
  const int block = std::max(64, n / 50);
  for (int first = 0; first < n; first += block) {
    report_progress(progress, Stage::Placement, first, n);
    tbb::parallel_for(first, std::min(n, first + block), [&](int i) {
      const size_t k = static_cast<size_t>(i);
      outcome[k] = placer.place(copies[k], out[k], proxy[k]);
    });
  }
  std::vector<PlacedPiece> placed;
  for (size_t i = 0; i < copies.size(); ++i) {
    gstats.off_surface += outcome[i] == kPieceOff;
    gstats.pieces_distorted += outcome[i] == kPieceDistorted;
    gstats.pieces_near_cones += outcome[i] == kPieceNearCone;
    if (outcome[i] != kPiecePlaced) continue;
    placed.push_back(std::move(out[i]));
    positions->push_back(std::move(proxy[i]));
  }
  gstats.thread_pieces = static_cast<int>(placed.size());
  return placed;
}

// The pieces to leave out of the welded threads (#pieces flags): as few as leave no two
// intersecting once embedded by normal displacement (greedy_vertex_cover), and, when
// drop_folded says the quilt will be embedded so, those folded through themselves. The pieces
// of a thread share their loops and do not count as touching there.
std::vector<char> intersecting_thread_pieces(const SurfaceJob& job, const MatrixX3d& N,
                                             const std::vector<SurfaceElement>& threads,
                                             const std::vector<std::vector<int>>& face_piece,
                                             size_t num_pieces, bool drop_folded,
                                             GlobalQuiltingStats& gstats) {
  std::vector<Eigen::Index> first(threads.size() + 1, 0), first_face(threads.size() + 1, 0);
  for (size_t k = 0; k < threads.size(); ++k) {
    first[k + 1] = first[k] + static_cast<Eigen::Index>(threads[k].face.size());
    first_face[k + 1] = first_face[k] + threads[k].F.rows();
  }
  MatrixX3d V(first.back(), 3);
  MatrixX3i F(first_face.back(), 3);
  std::vector<int> piece_of(static_cast<size_t>(first_face.back()));
  tbb::parallel_for(size_t{0}, threads.size(), [&](size_t k) {
    const SurfaceElement& e = threads[k];
    for (size_t v = 0; v < e.face.size(); ++v) {
      const Eigen::Index r = static_cast<Eigen::Index>(v);
      V.row(first[k] + r) = displace_along_normal(job.base, N, e.face[v],
                                                  e.barycentric.row(r).transpose(), e.height(r))
                                .transpose();
    }
    F.middleRows(first_face[k], e.F.rows()) = e.F.array() + static_cast<int>(first[k]);
    std::copy(face_piece[k].begin(), face_piece[k].end(), piece_of.begin() + first_face[k]);
  });
  // Pairs within a piece matter only when its folds do: else only pieces meeting each other are
  // tested (most face pairs whose boxes meet are neighbours in one piece; the cup's weave job:
  // placement 0.71-1.05 -> 0.39-0.43 s, the same pieces dropped).
  std::vector<std::pair<int, int>> pairs;
  if (drop_folded) {
    IntersectionOptions io;
    io.between_components_only = false;
    pairs = intersecting_face_pairs(V, F, io);
  } else {
    pairs = intersecting_face_pairs_between(V, F, piece_of);
  }
  std::vector<char> drop(num_pieces, 0);
  std::vector<std::pair<int, int>> touching;
  for (const auto& [f, g] : pairs) {
    const int a = piece_of[static_cast<size_t>(f)], b = piece_of[static_cast<size_t>(g)];
    if (a != b)
      touching.emplace_back(a, b);
    else if (drop_folded)
      drop[static_cast<size_t>(a)] = 1;
  }
  greedy_vertex_cover(touching, drop);
  gstats.pieces_intersecting = static_cast<int>(std::count(drop.begin(), drop.end(), 1));
  return drop;
}

// Under a region (a mask, SurfaceQuiltingOptions::region: per face of job.base): the pieces most
// of whose vertices lie outside it are dropped too, so that threads end (capped) at its border
// rather than run on whole past it.
void drop_pieces_outside(const std::vector<char>& region, const std::vector<PlacedPiece>& placed,
                         std::vector<char>& drop) {
  drop.resize(placed.size(), 0);
  for (size_t k = 0; k < placed.size(); ++k) {
    const std::vector<int>& faces = placed[k].element.face;
    const auto outside = std::count_if(faces.begin(), faces.end(),
                                       [&](int f) { return region[static_cast<size_t>(f)] == 0; });
    if (2 * static_cast<size_t>(outside) > faces.size()) drop[k] = 1;
  }
}

// A periodic swatch of threads (core/surface/thread_tiling) carried onto the base: every lattice
// copy of every thread piece whose centre lies on the parameterised surface, placed through the
// layout like place_lattice's elements, then welded end to end into threads. A piece is left out,
// and its threads end there:
// - where the layout bends it beyond kThreadShapeLimit (within_shape_limits);
// - within one thread spacing of a cone. Straight threads wrap round cones: a cone of angle pi
//   (a + cone of the line field) turns a line passing it by a half turn, in a hairpin as tight
//   as the line passes close. These were the U-turns of --method global (every sharp turn of a
//   thread within the tangent plane on the cup and the bunny lay 0.7-1.5 spacings from a +
//   cone); a thread farther away turns round it in a wide arc;
// - where, embedded by normal displacement, it intersects another piece (as few left out as can
//   be, greedy_vertex_cover: the embedding removes whole elements, and an element here is a
//   whole thread; bunny + weave: 103 threads removed after the shell map without this), or
//   folds through itself when options.global.drop_folded_pieces says the quilt will be
//   embedded so (the shell map unfolds them: 148 of the bunny's 1,642 pieces fold under
//   normal displacement, none after the shell map).
// The work follows the surface's parameter area. unfit (optional): set, and nothing returned,
// when the layout does not carry the pieces (layout_carries_threads).
std::vector<SurfaceElement> place_threads(const GlobalParameterization& gp, const SurfaceJob& job,
                                          const ThreadTiling& tiling, const SwatchSymmetry& sym,
                                          const Vector2d& lo, double shell_height,
                                          const SurfaceQuiltingOptions& options,
                                          GlobalQuiltingStats& gstats, StageTimes& times,
                                          ProgressSink* progress, bool* unfit = nullptr) {
  std::vector<LatticeCopy> copies;
  {
    ScopedStage stage(times, progress, Stage::Tiling);
    copies = thread_piece_copies(gp, job, tiling, sym, lo, options, gstats);
  }
  ScopedStage stage(times, progress, Stage::Placement);
  const MatrixX3d N = vertex_normals(job.base.V, job.base.F);
  std::vector<MatrixX3d> positions;
  std::vector<PlacedPiece> placed = place_thread_copies(
      ThreadPiecePlacer(gp, job, tiling, sym, lo, shell_height, options.global, N), copies,
      &positions, gstats, progress);
  // A piece is a part of its swatch thread, vertex for vertex (issue 25, swatch animation).
  if (options.keep_sources)
    for (PlacedPiece& p : placed) {
      const ThreadPiece& piece = tiling.pieces[static_cast<size_t>(p.piece)];
      p.element.source = piece.V;
      p.element.source_element.assign(static_cast<size_t>(piece.V.rows()), piece.source);
    }
  // Decided on the pieces' outcomes alone, before they are welded and tested for
  // intersections (the wicker chair: 1.2 s of the 2.1 s its placement took).
  if (unfit && !layout_carries_threads(gstats)) {
    *unfit = true;
    return {};
  }
  const std::vector<ThreadWeld> welds =
      find_thread_welds(placed, tiling, [&](int k, int v) -> Vector3d {
        return positions[static_cast<size_t>(k)].row(v).transpose();
      });
  ThreadWeldStats ws;
  std::vector<std::vector<int>> face_piece;
  std::vector<SurfaceElement> threads = weld_threads(placed, tiling, welds, {}, &ws, &face_piece);
  std::vector<char> drop = intersecting_thread_pieces(job, N, threads, face_piece, placed.size(),
                                                      options.global.drop_folded_pieces, gstats);
  if (options.region) drop_pieces_outside(options.region(job.base), placed, drop);
  threads = weld_threads(placed, tiling, welds, drop, &ws, nullptr, kMinThreadPieces);
  gstats.thread_welds = ws.welds;
  gstats.thread_ends = ws.caps;
  gstats.closed_threads = ws.closed_threads;
  gstats.short_threads = ws.short_threads;
  return threads;
}

// The line field whose singularities are the layout's first cones, on the smoothed copy V of
// the base. The guidance (the user's field, or the smooth default along the longest box axis)
// is followed weakly; when that leaves a pole (an index-1 singularity), the smoothest line
// field, turned towards the guidance. Always the smoothest field measured worse on the shipped
// bases (interior rings with 4 links, weighted / smoothest: knight 87.9 / 72.1%, bunny 96.5 /
// 94.3%, Spot 95.3 / 94.0%, cup 98.4 / 97.8%); the weighted fit left poles on a smoothed
// icosphere. A pole left even so (Blender's UV sphere: both poles, where 32 thin triangles
// meet) is split by the cone placement.
DirectionField layout_line_field(const MatrixX3d& V, const SurfaceJob& job,
                                 const SurfaceQuiltingOptions::Global& options,
                                 GlobalQuiltingStats& gstats) {
  const MatrixX3i& F = job.base.F;
  LineFieldOptions lo;
  lo.N = 2;
  lo.guidance_weight = options.guidance_weight;
  DirectionField df = smooth_direction_field(V, F, job.topo, job.TT, job.field, lo);
  const auto has_pole = [](const DirectionField& f) {
    for (const int i : f.index)
      if (i != 0 && i % f.N == 0) return true;
    return false;
  };
  if (has_pole(df)) {
    lo.smoothest = true;
    df = smooth_direction_field(V, F, job.topo, job.TT, job.field, lo);
  }
  // A + and a - cone side by side (the tip and the foot of a spike one ring across) serve no
  // ring and each wrecks the rings around it (knight: 8 such pairs of 42 cones; rings off the
  // surface 63 -> 17; with ring separation, interior rings with 4 links 89.5 -> 91.3%).
  if (options.cancel_cone_pairs)
    gstats.cancelled_cone_pairs = cancel_singular_pairs(V, F, job.topo, df);
  return df;
}

// The thread pieces cut at full detail, then simplified to the swatch's (reduce_piece_detail).
ThreadTiling detailed_thread_tiling(const PreparedSwatch& swatch, const PreparedSwatch& full,
                                    const SwatchSymmetry& symmetry) {
  ThreadTiling tiling = thread_tiling(full, symmetry);
  if (&full != &swatch) reduce_piece_detail(tiling, full, swatch);
  return tiling;
}

// The cones moved to where they flatten the surface with the least change of scale, and the
// field made parallel in their flat metric, whose scale e^u the layout then follows: the map is
// conformal, elements keep their shape (issue 23: rings on a sphere were 1.14x by 0.75x the
// swatch's, median aspect 1.9). False, df and face_scale unchanged, when the cones of some
// component do not balance (the layout then follows the line field at unit scale).
bool conformal_layout_field(const SurfaceJob& job, const SurfaceQuiltingOptions::Global& options,
                            DirectionField& df, Eigen::VectorXd& face_scale,
                            GlobalQuiltingStats& gstats) {
  const TriMesh& base = job.base;
  const TrivialConnection connection(base.V, base.F, job.topo, job.TT, df.N);
  if (connection.unbalanced_component(df.index) >= 0) return false;
  ConePlacementReport report;
  ConePlacementOptions placement;
  placement.pair_allowance = options.cone_pair_allowance;
  // A size map: the layout's scale is the inverse of the element size.
  if (job.log_size.size()) placement.target = -job.log_size;
  const std::vector<int> cones = place_cones(
      connection, df.index, vertex_adjacency(base.F, base.num_vertices()), placement, &report);
  gstats.split_poles = report.split_poles;
  gstats.cone_moves = report.moves;
  gstats.placement_pairs_cancelled = report.pairs_cancelled;
  gstats.scale_energy_before = report.energy_before;
  gstats.scale_energy = report.energy_after;
  // On a boundary the metric's scale is free: held to the size map's there (0 without one).
  const ConeMetric metric = connection.solve(cones, job.field, placement.target);
  df = metric.field;
  // A metric that scales the surface unevenly (e^u, log-normal with variance E) is followed
  // only partly, e^(a u): normalised to keep the typical element's size, the lattice fills the
  // surface about e^(2 a^2 E) times over, kept under max_overfill. Measured on the knight at the
  // armor job's scale (E 0.17), interior rings with 4 links / density / median ring: a = 1:
  // 73.2% / 117% / 0.85x; a = 0.5: 71.3% / 94% / 0.91x; a = 0 (the field at unit scale): 69.7%
  // / 90% / 0.95x. The dragon scan (372 cones, E 0.69) filled 8 times over at a = 1, with rings
  // at 0.37x.
  const double E = report.energy_after;
  gstats.scale_exponent =
      E > 0 ? std::min(1.0, std::sqrt(std::log(options.max_overfill) / (2 * E))) : 1.0;
  // With a size map the part of u that misses it (r) is what is followed only partly: the
  // scale is e^(u - (1 - a) r), e^u where a = 1.
  const double a = gstats.scale_exponent;
  Eigen::VectorXd log_scale = metric.u;
  if (placement.target.size())
    log_scale -= (1 - a) * misfit(connection, metric.u, placement.target);
  // Without a map e^(a u), rounded as before (a times the corners' sum).
  const double factor = placement.target.size() ? 1.0 : a;
  face_scale.resize(base.num_faces());
  for (int f = 0; f < base.num_faces(); ++f)
    face_scale(f) = std::exp(
        factor * (log_scale(base.F(f, 0)) + log_scale(base.F(f, 1)) + log_scale(base.F(f, 2))) / 3);
  return true;
}

// The base's global parameterisation (the plane texture's layout over it), seamless at the
// swatch's symmetries when options.seamless. The line field is found on a smoothed copy of the
// base (same connectivity): detail of an edge's size would otherwise put a cone at every sharp
// corner of a coarse model. Measured, interior rings with the swatch's 4 links, without / with
// one step: Spot 93.8 / 95.5%, knight 82.3 / 87.3%, bunny 95.7 / 96.8%, cup 97.9 / 98.6% (before
// the conformal layout, which keeps the field's cones but moves them and lays the texture out on
// the base itself: the layout computed on the smoothed copy and carried back to the base by
// barycentric coordinates took on the smoothing's tangential drift, median element aspect 1.12
// against 1.05 on Spot). anchor: where the plane quilt's coordinates start.
GlobalParameterization global_layout(const SurfaceJob& job, const SwatchSymmetry& symmetry,
                                     const SurfaceQuiltingOptions::Global& options,
                                     Vector2d& anchor, GlobalQuiltingStats& gstats,
                                     StageTimes& times, ProgressSink* progress) {
  ScopedStage stage(times, progress, Stage::Parameterization);
  const TriMesh& base = job.base;
  const MatrixX3d smoothed =
      options.smoothing > 0 ? smoothed_positions(base, job.topo, options.smoothing) : base.V;
  DirectionField df = layout_line_field(smoothed, job, options, gstats);
  Eigen::VectorXd face_scale;
  const MatrixX3d* layout_V = &smoothed;
  if (options.conformal && conformal_layout_field(job, options, df, face_scale, gstats)) {
    layout_V = &base.V;
  } else if (job.log_size.size()) {
    // Without the cone metric the field is not made parallel for it: followed by least squares.
    face_scale.resize(base.num_faces());
    for (int f = 0; f < base.num_faces(); ++f) face_scale(f) = 1 / nominal_size(job, f);
  }
  return seamless_parameterization(*layout_V, base, job, df, face_scale, symmetry, options.seamless,
                                   anchor, gstats);
}

// The lower corner of the parameter plane's box, where the plane texture starts. Seamless, the
// plane's origin stays at the anchor, moved back by a lattice vector if the parameterisation
// reaches beyond it.
Vector2d plane_origin(const GlobalParameterization& gp, const SwatchSymmetry& symmetry,
                      const Vector2d& anchor, const GlobalQuiltingStats& gstats) {
  Vector2d lo = gp.wedge_uv.colwise().minCoeff().transpose();
  if (gstats.seamless) {
    const Vector2d need = (anchor - lo).cwiseMax(0.0);
    Vector2d shift = Vector2d::Zero();
    if (need.squaredNorm() > 0)
      shift = nearest_symmetry(symmetry,
                               need + Vector2d::Constant(symmetry.a.norm() + symmetry.b.norm()),
                               Vector2d::Zero());
    lo = anchor - shift;
  }
  return lo;
}

// The swatch quilted over the parameter plane's box [lo, hi] (section 2's planar quilting, its
// stages' figures and times into stats), then carried onto the base (place_plane).
std::vector<SurfaceElement> place_quilted_plane(
    const GlobalParameterization& gp, const SurfaceJob& job, const PreparedSwatch& swatch,
    const Vector2d& lo, const Vector2d& hi, const SurfaceQuiltingOptions& options,
    TranslationCostEvaluator& evaluator, SurfaceQuiltingStats& stats, GlobalQuiltingStats& gstats,
    ProgressSink* progress) {
  PlanarQuiltingOptions po;
  po.length = std::max(hi.x() - lo.x(), swatch.size.x());
  po.width = std::max(hi.y() - lo.y(), swatch.size.y());
  po.matching = options.matching;
  po.matching.refine_to = PlanarQuiltingOptions().matching.refine_to;
  po.correspondence = options.patch.correspondence;
  po.merging = options.patch.merging;
  po.deform = options.patch.deform;
  po.seed = options.seed;
  po.max_faces = options.max_faces;
  gstats.parameter_area = po.length * po.width;
  PlanarQuiltingStats ps;
  PlaneSources sources;
  TriMesh plane = quilt_plane(job.swatch, po, evaluator, &ps, progress,
                              options.keep_sources ? &sources : nullptr);
  stats.iterations = ps.iterations;
  stats.cell_size = ps.cell_size;
  stats.matched_point_offsets = ps.matched_point_offsets;
  stats.counts = ps.counts;
  stats.times.merge(ps.times);
  // Back into the synthesis frame (thickness along z).
  plane.V = (plane.V * swatch.rotation.transpose()).eval();
  plane.V.col(0).array() += lo.x();
  plane.V.col(1).array() += lo.y();
  return place_plane(gp, job, plane, options.keep_sources ? &sources : nullptr, swatch.size.z(),
                     gstats, stats.times, progress);
}

// The quilt of the elements placed over the base, and its counts.
SurfaceQuilt global_surface_quilt(SurfaceJob& job, const PreparedSwatch& swatch,
                                  std::vector<SurfaceElement> placed, SurfaceQuiltingStats& stats) {
  SurfaceQuilt quilt;
  quilt.kinds = swatch.kinds;
  quilt.shell_height = swatch.size.z();
  quilt.base = job.base;
  take_input_bases(job, quilt);
  quilt.elements = std::move(placed);
  stats.elements = static_cast<int>(quilt.elements.size());
  for (const SurfaceElement& e : quilt.elements) {
    stats.faces += static_cast<int>(e.F.rows());
    stats.vertices += static_cast<int>(e.face.size());
  }
  return quilt;
}

// The global method from a prepared job and the swatch's symmetry (found on `full`: the swatch
// at full detail, `swatch` itself unless job.full_swatch was given). threads: the swatch's
// thread tiling at swatch's detail when known (empty: found here when the swatch is no
// lattice of compact elements). unfit (optional): set, and nothing placed or returned, when the
// swatch is a lattice of threads and the layout cannot carry its tiling
// (layout_fit_for_tiling); the caller quilts otherwise.
SurfaceQuilt quilt_prepared_global(SurfaceJob& job, const PreparedSwatch& swatch,
                                   const PreparedSwatch& full, const SwatchSymmetry& symmetry,
                                   ThreadTiling threads, const SurfaceQuiltingOptions& options,
                                   TranslationCostEvaluator& evaluator, SurfaceQuiltingStats stats,
                                   SurfaceQuiltingStats* stats_out, GlobalQuiltingStats* global_out,
                                   ProgressSink* progress, bool* unfit = nullptr) {
  GlobalQuiltingStats gstats;
  StageTimes& times = stats.times;
  stats.shell_height = swatch.size.z();
  gstats.periodic = symmetry.periodic;
  Vector2d anchor = Vector2d::Zero();
  const GlobalParameterization gp =
      global_layout(job, symmetry, options.global, anchor, gstats, times, progress);
  gstats.singular_vertices = gp.num_singular;
  gstats.cones = cone_positions(gp, job.base);
  gstats.cut_edges = gp.num_cut_edges;
  const Vector2d lo = plane_origin(gp, symmetry, anchor, gstats);
  const Vector2d hi = gp.wedge_uv.colwise().maxCoeff().transpose();

  std::vector<SurfaceElement> placed;
  if (options.global.tile && tileable(full, symmetry)) {
    gstats.tiled = true;
    stats.iterations = 1;
    stats.cell_size = matching_cell_size(swatch);
    placed = place_lattice(gp, job, swatch, full, symmetry, lo, options, gstats, times, progress);
  } else if (options.global.tile &&
             !(threads.empty() ? (threads = detailed_thread_tiling(swatch, full, symmetry))
                               : threads)
                  .empty()) {
    if (unfit && !layout_fit_for_tiling(gp, job.base)) {
      *unfit = true;
      return {};
    }
    gstats.threads = true;
    stats.iterations = 1;
    stats.cell_size = matching_cell_size(swatch);
    if (!options.global.count_only)
      placed = place_threads(gp, job, threads, symmetry, lo, swatch.size.z(), options, gstats,
                             times, progress, unfit);
    if (unfit && *unfit) return {};
  } else if (!options.global.count_only) {
    placed =
        place_quilted_plane(gp, job, swatch, lo, hi, options, evaluator, stats, gstats, progress);
  }
  gstats.placed = static_cast<int>(placed.size());
  SurfaceQuilt quilt = global_surface_quilt(job, swatch, std::move(placed), stats);
  quilt.stitched = !gstats.tiled;  // the plane quilt's elements, the threads welded of pieces
  report_progress(progress, Stage::Quilting, 1, 1);
  if (stats_out) *stats_out = std::move(stats);
  if (global_out) *global_out = gstats;
  return quilt;
}

SwatchSymmetry timed_symmetry(const PreparedSwatch& swatch, StageTimes& times) {
  ScopedStageTimer timer(times, Stage::Symmetry);
  const SwatchFaceTree tree(swatch.mesh.V, swatch.mesh.F);
  return detect_swatch_symmetry(swatch, tree, matching_cell_size(swatch));
}

}  // namespace

SurfaceQuilt quilt_surface_global(const TriMesh& base_in, const TriMesh& swatch_mesh,
                                  const SurfaceQuiltingOptions& options,
                                  TranslationCostEvaluator& evaluator,
                                  SurfaceQuiltingStats* stats_out, GlobalQuiltingStats* global_out,
                                  ProgressSink* progress) {
  SurfaceQuiltingStats stats;
  SurfaceJob job = prepare_surface_job(base_in, swatch_mesh, options, stats);
  const PreparedSwatch swatch = prepare_swatch(job.swatch);
  PreparedSwatch full;
  const PreparedSwatch& deciding = swatch_at_full_detail(job, swatch, full);
  const SwatchSymmetry symmetry = timed_symmetry(deciding, stats.times);
  return quilt_prepared_global(job, swatch, deciding, symmetry, {}, options, evaluator,
                               std::move(stats), stats_out, global_out, progress);
}

SurfaceQuilt quilt_surface_auto(const TriMesh& base_in, const TriMesh& swatch_mesh,
                                const SurfaceQuiltingOptions& options,
                                TranslationCostEvaluator& evaluator,
                                SurfaceQuiltingStats* stats_out, GlobalQuiltingStats* global_out,
                                ProgressSink* progress, bool* used_global, bool* used_vines,
                                VineGrowthStats* vine_stats) {
  SurfaceQuiltingStats stats;
  SurfaceJob job = prepare_surface_job(base_in, swatch_mesh, options, stats);
  const PreparedSwatch swatch = prepare_swatch(job.swatch);
  // The method and the lattice are decided at full detail (a Preview is the same layout).
  PreparedSwatch full;
  const PreparedSwatch& deciding = swatch_at_full_detail(job, swatch, full);
  bool repeating = false, threads = false;
  {
    ScopedStageTimer timer(stats.times, Stage::MethodChoice);
    repeating = repeating_elements(deciding);
    threads = !repeating && long_elements(deciding);
  }
  if (repeating || threads) {
    // The symmetry decides and, for a lattice, is the one the layout uses: found once.
    const SwatchSymmetry symmetry = timed_symmetry(deciding, stats.times);
    ThreadTiling tiling;
    bool global = false;
    {
      ScopedStageTimer timer(stats.times, Stage::MethodChoice);
      global = repeating ? tileable(deciding, symmetry)
                         : !(tiling = detailed_thread_tiling(swatch, deciding, symmetry)).empty();
    }
    if (global && repeating) {
      if (used_global) *used_global = true;
      return quilt_prepared_global(job, swatch, deciding, symmetry, std::move(tiling), options,
                                   evaluator, std::move(stats), stats_out, global_out, progress);
    }
    if (global) {
      // Threads: the layout is made first, and where it cannot carry the tiling (a base of
      // many small, rough parts) the patches quilt the job instead.
      const auto start = std::chrono::steady_clock::now();
      bool unfit = false;
      SurfaceQuilt quilt =
          quilt_prepared_global(job, swatch, deciding, symmetry, std::move(tiling), options,
                                evaluator, stats, stats_out, global_out, progress, &unfit);
      if (!unfit) {
        if (used_global) *used_global = true;
        return quilt;
      }
      stats.times.add(
          Stage::UnfitLayout,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  }
  if (used_global) *used_global = false;
  if (used_vines) *used_vines = false;
  bool vines = false;
  {
    ScopedStageTimer timer(stats.times, Stage::MethodChoice);
    vines = is_vine_swatch(deciding);
  }
  if (vines) {
    if (used_vines) *used_vines = true;
    return quilt_prepared_vines(std::move(job), std::move(stats), options, VineGrowthOptions{},
                                stats_out, vine_stats, progress);
  }
  if (options.global.count_only) {  // the preparation's estimate is the patches'
    if (stats_out) *stats_out = std::move(stats);
    return {};
  }
  // The job prepared once (a large base is simplified in the preparation).
  return quilt_prepared_surface(std::move(job), std::move(stats), options, evaluator, stats_out,
                                progress);
}

}  // namespace mq
