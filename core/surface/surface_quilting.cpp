#include "core/surface/surface_quilting.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/fins.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/outward_orientation.h"
#include "core/mesh/quadric_simplification.h"
#include "core/mesh/weld_vertices.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/quilt_elements.h"
#include "core/surface/local_patch.h"
#include "core/surface/tangent_field.h"

namespace mq {

namespace {

// Barycentric coordinates of p's orthogonal projection onto the plane of (a, b, c); they are not
// clamped, so points beyond the triangle extrapolate its affine map.
Vector3d plane_barycentric(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                           const Vector3d& c) {
  const Vector3d e0 = b - a, e1 = c - a, d = p - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double d20 = d.dot(e0), d21 = d.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return Vector3d(1, 0, 0);
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return Vector3d(1 - v - w, v, w);
}

Vector3d triangle_barycentric_2d(const Vector2d& p, const Vector2d& a, const Vector2d& b,
                                 const Vector2d& c) {
  const Vector2d e0 = b - a, e1 = c - a, d = p - a;
  const double den = e0.x() * e1.y() - e1.x() * e0.y();
  if (!(std::abs(den) > 0)) return Vector3d(1, 0, 0);
  const double v = (d.x() * e1.y() - e1.x() * d.y()) / den;
  const double w = (e0.x() * d.y() - d.x() * e0.y()) / den;
  return Vector3d(1 - v - w, v, w);
}

// A flattened local patch in the synthesis frame: the LSCM map rotated so that the guidance
// field points along +x at the seed and translated so the seed's centroid is the origin.
class PatchFrame {
 public:
  // device: where the BVH for points beyond the patch is built when first needed.
  PatchFrame(const TriMesh& base, LocalPatch patch, const Vector3d& direction,
             const EmbreeDevice& device)
      : base_(base), patch_(std::move(patch)), device_(device) {
    const MatrixX3i& F = patch_.mesh.F;
    for (int f = 0; f < F.rows(); ++f) local_of_[patch_.faces[f]] = f;
    // The seed face's affine map takes the 3D field direction into the UV plane.
    const int s = 0;
    const Vector3d a = patch_.mesh.V.row(F(s, 0)), b = patch_.mesh.V.row(F(s, 1)),
                   c = patch_.mesh.V.row(F(s, 2));
    const Vector2d ua = patch_.uv.row(F(s, 0)), ub = patch_.uv.row(F(s, 1)),
                   uc = patch_.uv.row(F(s, 2));
    const Vector3d w = plane_barycentric(a + direction, a, b, c);
    Vector2d d = w(0) * ua + w(1) * ub + w(2) * uc - ua;
    if (!(d.norm() > 0)) d = Vector2d(1, 0);
    d.normalize();
    const Vector2d origin = (ua + ub + uc) / 3.0;
    uv_.resize(patch_.uv.rows(), 2);
    for (int v = 0; v < patch_.uv.rows(); ++v) {
      const Vector2d q = patch_.uv.row(v).transpose() - origin;
      uv_.row(v) << q.dot(d), q.x() * -d.y() + q.y() * d.x();
    }
    build_grid();
  }

  const LocalPatch& patch() const { return patch_; }
  const MatrixX2d& uv() const { return uv_; }
  int local_face(int base_face) const {
    auto it = local_of_.find(base_face);
    return it == local_of_.end() ? -1 : it->second;
  }

  // Frame position of a local coordinate; beyond the patch, through the nearest patch face.
  Vector2d to_frame(int base_face, const Vector3d& bary) const {
    int f = local_face(base_face);
    Vector3d w = bary;
    if (f < 0) {
      const Vector3d p = bary(0) * base_.V.row(base_.F(base_face, 0)).transpose() +
                         bary(1) * base_.V.row(base_.F(base_face, 1)).transpose() +
                         bary(2) * base_.V.row(base_.F(base_face, 2)).transpose();
      // Built on first use: most patches never need it, and a BVH per patch is not free.
      if (!query_)
        query_ = std::make_unique<ClosestPointQuery>(device_, patch_.mesh.V, patch_.mesh.F);
      f = query_->closest(p).face;
      const MatrixX3i& F = patch_.mesh.F;
      w = plane_barycentric(p, patch_.mesh.V.row(F(f, 0)), patch_.mesh.V.row(F(f, 1)),
                            patch_.mesh.V.row(F(f, 2)));
    }
    const MatrixX3i& F = patch_.mesh.F;
    return w(0) * uv_.row(F(f, 0)).transpose() + w(1) * uv_.row(F(f, 1)).transpose() +
           w(2) * uv_.row(F(f, 2)).transpose();
  }

  // The patch face containing frame point q (true) or the nearest one (false, with barycentric
  // coordinates extrapolating it).
  bool locate(const Vector2d& q, int& face, Vector3d& bary) const {
    const MatrixX3i& F = patch_.mesh.F;
    face = -1;
    double best = std::numeric_limits<double>::infinity();
    const int cx = std::clamp(static_cast<int>((q.x() - lo_.x()) / cell_), 0, nx_ - 1);
    const int cy = std::clamp(static_cast<int>((q.y() - lo_.y()) / cell_), 0, ny_ - 1);
    // Ring search over the grid: the first containing triangle wins; else the nearest by the
    // most negative barycentric coordinate over the rings visited.
    for (int r = 0; r < std::max(nx_, ny_); ++r) {
      for (int y = cy - r; y <= cy + r; ++y)
        for (int x = cx - r; x <= cx + r; ++x) {
          if (std::max(std::abs(x - cx), std::abs(y - cy)) != r) continue;
          if (x < 0 || y < 0 || x >= nx_ || y >= ny_) continue;
          for (const int f : cells_[y * nx_ + x]) {
            const Vector3d w =
                triangle_barycentric_2d(q, uv_.row(F(f, 0)), uv_.row(F(f, 1)), uv_.row(F(f, 2)));
            const double outside = -w.minCoeff();
            if (outside <= 1e-9) {
              face = f;
              bary = w;
              return true;
            }
            if (outside < best || (outside == best && f < face)) {
              best = outside;
              face = f;
              bary = w;
            }
          }
        }
      if (face >= 0 && r >= 1) break;
    }
    return false;
  }

  // Frame position of the centroid of patch face f.
  Vector2d face_centroid(int f) const {
    const MatrixX3i& F = patch_.mesh.F;
    return (uv_.row(F(f, 0)) + uv_.row(F(f, 1)) + uv_.row(F(f, 2))).transpose() / 3.0;
  }

  // Minimum distance from q to the patch's boundary in the frame.
  double distance_to_border(const Vector2d& q) const {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [i, j] : border_) {
      const Vector2d a = uv_.row(i), b = uv_.row(j), d = b - a;
      const double t =
          d.squaredNorm() > 0 ? std::clamp((q - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      best = std::min(best, (a + t * d - q).norm());
    }
    return best;
  }

 private:
  void build_grid() {
    const MatrixX3i& F = patch_.mesh.F;
    lo_ = uv_.colwise().minCoeff().transpose();
    const Vector2d hi = uv_.colwise().maxCoeff().transpose();
    const double side = std::max((hi - lo_).maxCoeff(), 1e-12);
    const int n = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(F.rows()))));
    cell_ = side / n;
    nx_ = std::max(1, static_cast<int>((hi.x() - lo_.x()) / cell_) + 1);
    ny_ = std::max(1, static_cast<int>((hi.y() - lo_.y()) / cell_) + 1);
    cells_.assign(static_cast<size_t>(nx_) * ny_, {});
    for (int f = 0; f < F.rows(); ++f) {
      Vector2d a = uv_.row(F(f, 0)), b = a;
      for (int k = 1; k < 3; ++k) {
        a = a.cwiseMin(uv_.row(F(f, k)).transpose());
        b = b.cwiseMax(uv_.row(F(f, k)).transpose());
      }
      const int x0 = std::clamp(static_cast<int>((a.x() - lo_.x()) / cell_), 0, nx_ - 1);
      const int x1 = std::clamp(static_cast<int>((b.x() - lo_.x()) / cell_), 0, nx_ - 1);
      const int y0 = std::clamp(static_cast<int>((a.y() - lo_.y()) / cell_), 0, ny_ - 1);
      const int y1 = std::clamp(static_cast<int>((b.y() - lo_.y()) / cell_), 0, ny_ - 1);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) cells_[y * nx_ + x].push_back(f);
    }
    const EdgeTopology topo = edge_topology(F, static_cast<int>(uv_.rows()));
    for (int e = 0; e < topo.num_edges(); ++e)
      if (topo.is_boundary(e)) border_.emplace_back(topo.E(e, 0), topo.E(e, 1));
  }

  const TriMesh& base_;
  LocalPatch patch_;
  MatrixX2d uv_;
  std::unordered_map<int, int> local_of_;
  Vector2d lo_ = Vector2d::Zero();
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
  std::vector<std::pair<int, int>> border_;
  const EmbreeDevice& device_;
  mutable std::unique_ptr<ClosestPointQuery> query_;
};

// 2D points binned in a uniform hash grid of cell `radius`, answering "is any point within
// radius of q" by looking at the 3 x 3 cells around q.
class PointsNear2D {
 public:
  explicit PointsNear2D(double radius) : r_(radius) {}
  void add(const Vector2d& p) { cells_[key(cell_of(p.x()), cell_of(p.y()))].push_back(p); }
  bool any_within(const Vector2d& q) const {
    const long long cx = cell_of(q.x()), cy = cell_of(q.y());
    for (long long y = cy - 1; y <= cy + 1; ++y)
      for (long long x = cx - 1; x <= cx + 1; ++x) {
        auto it = cells_.find(key(x, y));
        if (it == cells_.end()) continue;
        for (const Vector2d& p : it->second)
          if ((p - q).squaredNorm() <= r_ * r_) return true;
      }
    return false;
  }

 private:
  long long cell_of(double v) const { return static_cast<long long>(std::floor(v / r_)); }
  static long long key(long long x, long long y) { return x * 73856093LL ^ y * 19349663LL; }
  double r_;
  std::unordered_map<long long, std::vector<Vector2d>> cells_;
};

// The output elements in local coordinates, with an index from base faces to the elements that
// have vertices above them.
struct SurfaceStore {
  std::vector<SurfaceElement> elements;
  std::vector<unsigned char> alive;
  std::vector<std::vector<int>> by_face;

  explicit SurfaceStore(int num_faces) : by_face(num_faces) {}
  void index(int id) {
    std::vector<int> faces = elements[id].face;
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    for (const int f : faces)
      if (by_face[f].empty() || by_face[f].back() != id) by_face[f].push_back(id);
  }
  int add(SurfaceElement e) {
    elements.push_back(std::move(e));
    alive.push_back(1);
    index(static_cast<int>(elements.size()) - 1);
    return static_cast<int>(elements.size()) - 1;
  }
};

// The store seen through one patch frame: the elements near the patch, flattened.
class FramedOutput final : public PatchOutput {
 public:
  FramedOutput(SurfaceStore& store, std::map<int, Element> frame)
      : store_(store), frame_(std::move(frame)) {}

  const Element& element(int id) const override { return frame_.at(id); }
  bool alive(int id) const override { return store_.alive[id] != 0 && frame_.count(id); }
  std::vector<int> elements_near(const Vector2d& lo, const Vector2d& hi) const override {
    std::vector<int> ids;
    for (const auto& [id, e] : frame_)
      if (store_.alive[id] && e.lo.x() <= hi.x() && e.hi.x() >= lo.x() && e.lo.y() <= hi.y() &&
          e.hi.y() >= lo.y())
        ids.push_back(id);
    return ids;
  }
  int add(Element e) override {
    const int id = static_cast<int>(store_.elements.size());
    store_.elements.emplace_back();  // filled in local coordinates by the caller
    store_.alive.push_back(1);
    frame_[id] = std::move(e);
    changed_.insert(id);
    return id;
  }
  void replace(int id, Element e) override {
    frame_[id] = std::move(e);
    changed_.insert(id);
  }
  void remove(int id) override { store_.alive[id] = 0; }

  const std::set<int>& changed() const { return changed_; }
  const Element& frame_element(int id) const { return frame_.at(id); }

 private:
  SurfaceStore& store_;
  std::map<int, Element> frame_;
  std::set<int> changed_;
};

void validate_base(const TriMesh& base) {
  MQ_CHECK(base.F.rows() > 0, InvalidInput, "the base mesh has no faces");
  MQ_CHECK(base.V.allFinite(), InvalidInput, "the base mesh has non-finite vertex coordinates");
  for (int f = 0; f < base.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(base.F(f, k) >= 0 && base.F(f, k) < base.V.rows(), InvalidInput, "base face ", f,
               " references missing vertex ", base.F(f, k));
  // Checked here, in the user's terms, rather than by the step that would trip over it later
  // (issue 14: a zero-size base failed in the refinement, a degenerate face in the shell's
  // tetrahedra after 12 s of work, a base listed twice gave an empty result).
  const Vector3d extent = bounding_box(base.V, base.F).extent();
  MQ_CHECK(extent.allFinite(), InvalidInput,
           "the base mesh's coordinates are too large (its size overflows)");
  MQ_CHECK(extent.norm() > 0, InvalidInput,
           "the base mesh has zero size (all its vertices at one "
           "point)");
  for (int f = 0; f < base.F.rows(); ++f) {
    const int a = base.F(f, 0), b = base.F(f, 1), c = base.F(f, 2);
    MQ_CHECK(a != b && b != c && a != c, InvalidInput, "base face ", f,
             " repeats a vertex (a degenerate face); remove it from the base mesh");
  }
}

// The mesh without faces that repeat an earlier one (the same three vertices in the same
// orientation); input_face[f] is the face of `mesh` that face f of the result is. A base listed
// twice over gave an empty result (issue 14): the first of each is kept. The same triangle
// facing the other way is kept: it is the back of a two-sided sheet (the wicker chair has 35
// such pairs, and without their backs its patches meet non-manifold borders).
TriMesh without_duplicate_faces(const TriMesh& mesh, std::vector<int>& input_face, int* removed) {
  // Key: the face rotated to start at its smallest index (orientation kept), then the face.
  std::vector<std::array<int, 4>> sorted(static_cast<size_t>(mesh.F.rows()));
  for (int f = 0; f < mesh.F.rows(); ++f) {
    int r = 0;
    for (int k = 1; k < 3; ++k)
      if (mesh.F(f, k) < mesh.F(f, r)) r = k;
    sorted[static_cast<size_t>(f)] = {mesh.F(f, r), mesh.F(f, (r + 1) % 3), mesh.F(f, (r + 2) % 3),
                                      f};
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<char> keep(static_cast<size_t>(mesh.F.rows()), 1);
  for (size_t i = 1; i < sorted.size(); ++i)
    if (std::equal(sorted[i].begin(), sorted[i].begin() + 3, sorted[i - 1].begin()))
      keep[static_cast<size_t>(sorted[i][3])] = 0;  // sorted by index too: the later one goes
  input_face.clear();
  for (int f = 0; f < mesh.F.rows(); ++f)
    if (keep[static_cast<size_t>(f)]) input_face.push_back(f);
  *removed = mesh.F.rows() - static_cast<int>(input_face.size());
  if (*removed == 0) return mesh;
  TriMesh out;
  out.V = mesh.V;
  out.F.resize(static_cast<Eigen::Index>(input_face.size()), 3);
  for (size_t i = 0; i < input_face.size(); ++i)
    out.F.row(static_cast<Eigen::Index>(i)) = mesh.F.row(input_face[i]);
  return out;
}

// The mesh without its fins (core/mesh/fins.h): a piece sticking out of the surface at
// non-manifold edges cut the layout there on every side and took elements into it (issue 28,
// item 7: an ico sphere with a fin on every 7th edge, 88% covered after 13 s and a message
// blaming the scale; larger fins 1.9%). input_face and input_vertex are composed with the
// change. Unchanged (same vertex order) when there are none.
TriMesh without_fins(const TriMesh& mesh, std::vector<int>& input_face,
                     std::vector<int>& input_vertex, SurfaceQuiltingStats& stats) {
  const std::vector<int> fins = fin_faces(mesh, 10.0, &stats.non_manifold_edges);
  if (fins.empty()) return mesh;
  std::vector<char> fin(static_cast<size_t>(mesh.num_faces()), 0);
  for (const int f : fins) fin[static_cast<size_t>(f)] = 1;
  std::vector<int> keep, kept_input_face;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (!fin[static_cast<size_t>(f)]) {
      keep.push_back(f);
      kept_input_face.push_back(input_face[static_cast<size_t>(f)]);
    }
  MQ_CHECK(!keep.empty(), InvalidInput, "the base is made of fins only");
  const Eigen::VectorXd area = face_areas(mesh.V, mesh.F);
  double fin_area = 0;
  for (const int f : fins) fin_area += area(f);
  stats.fin_faces = static_cast<int>(fins.size());
  stats.fin_area_share = area.sum() > 0 ? fin_area / area.sum() : 0;
  std::vector<int> vertex_map;
  TriMesh out = extract_faces(mesh, keep, &vertex_map);
  if (!input_vertex.empty())
    for (int& v : vertex_map) v = input_vertex[static_cast<size_t>(v)];
  input_vertex = std::move(vertex_map);
  input_face = std::move(kept_input_face);
  return out;
}

}  // namespace

void to_input_base(const SurfaceQuilt& quilt, int& face, Vector3d& b) {
  if (!quilt.refinement.parent.empty()) to_parent(quilt.refinement, face, b);
}

Vector3d displace_along_normal(const TriMesh& base, const MatrixX3d& N, int face, const Vector3d& b,
                               double height) {
  Vector3d p = Vector3d::Zero(), n = Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    p += b(k) * base.V.row(base.F(face, k)).transpose();
    n += b(k) * N.row(base.F(face, k)).transpose();
  }
  if (n.norm() > 0) n.normalize();
  return p + height * n;
}

TriMesh embed_by_normal_displacement(const SurfaceQuilt& quilt) {
  const TriMesh& base = quilt.base;
  const MatrixX3d N = vertex_normals(base.V, base.F);
  TriMesh out;
  out.kinds = quilt.kinds;
  Eigen::Index nv = 0, nf = 0;
  for (const SurfaceElement& e : quilt.elements) {
    nv += static_cast<Eigen::Index>(e.face.size());
    nf += e.F.rows();
  }
  out.V.resize(nv, 3);
  out.F.resize(nf, 3);
  nv = nf = 0;
  for (const SurfaceElement& e : quilt.elements) {
    for (size_t v = 0; v < e.face.size(); ++v)
      out.V.row(nv + v) =
          displace_along_normal(base, N, e.face[v], e.barycentric.row(v).transpose(), e.height(v))
              .transpose();
    out.F.middleRows(nf, e.F.rows()) = e.F.array() + static_cast<int>(nv);
    out.face_kind.insert(out.face_kind.end(), static_cast<size_t>(e.F.rows()), e.kind);
    nv += static_cast<Eigen::Index>(e.face.size());
    nf += e.F.rows();
  }
  return out;
}

double longer_footprint_side(const TriMesh& swatch) {
  MQ_CHECK(swatch.num_faces() > 0, InvalidInput, "the swatch scale needs a non-empty swatch");
  const PreparedSwatch unit = prepare_swatch(swatch);
  return std::max(unit.size.x(), unit.size.y());
}

std::string size_option(const SurfaceQuiltingOptions& options) {
  std::ostringstream s;
  s << (options.element_size > 0 ? "--element-size " : "--scale ")
    << (options.element_size > 0 ? options.element_size : options.scale);
  return s.str();
}

double swatch_scale_for(const TriMesh& base, const TriMesh& swatch, double scale) {
  MQ_CHECK(std::isfinite(scale) && scale > 0, InvalidInput,
           "the swatch scale must be positive and finite, got ", scale);
  MQ_CHECK(base.num_faces() > 0 && swatch.num_faces() > 0, InvalidInput,
           "the swatch scale needs a non-empty base and swatch");
  const double diagonal = bounding_box(base.V, base.F).extent().norm();
  return scale * diagonal / longer_footprint_side(swatch);
}

SurfaceJob prepare_surface_job(const TriMesh& base_in, const TriMesh& swatch_mesh,
                               const SurfaceQuiltingOptions& options, SurfaceQuiltingStats& stats) {
  validate_base(base_in);
  MQ_CHECK(std::isfinite(options.base_edge_fraction) && options.base_edge_fraction > 0,
           InvalidInput, "base_edge_fraction must be positive and finite, got ",
           options.base_edge_fraction);
  MQ_CHECK(std::isfinite(options.scale) && options.scale > 0, InvalidInput,
           "the swatch scale must be positive and finite, got ", options.scale);
  MQ_CHECK(std::isfinite(options.element_size) && options.element_size >= 0, InvalidInput,
           "the element size must be positive and finite, got ", options.element_size);
  MQ_CHECK(options.proxy_min_faces >= 0 && std::isfinite(options.proxy_error) &&
               options.proxy_error >= 0,
           InvalidInput, "the base simplification needs a face count >= 0 and an error >= 0, got ",
           options.proxy_min_faces, " and ", options.proxy_error);
  MQ_CHECK(options.field.rows() == 0 || options.field.rows() == base_in.num_faces(), InvalidInput,
           "the guidance field has ", options.field.rows(), " vectors for ", base_in.num_faces(),
           " base faces");
  ScopedStageTimer timer(stats.times, "prepare");
  SurfaceJob job;
  // Exporters split vertices along hard edges; welded, a box's sides form one surface and
  // patches (and elements) can wrap around its edges.
  job.cleaned = weld_vertices(base_in, &stats.welded_vertices, &job.input_vertex);
  std::vector<int> input_face;  // job.cleaned's faces -> base_in's
  job.cleaned = without_duplicate_faces(job.cleaned, input_face, &stats.duplicate_faces);
  job.cleaned = without_fins(job.cleaned, input_face, job.input_vertex, stats);
  // The shell grows along the normal: components turned inside out would hide the texture
  // inside the object.
  if (options.orient_outward) stats.flipped_components = orient_outward(job.cleaned);
  // The output estimated before any work: the swatch's faces per unit of footprint area at its
  // scale on the surface, over the base's area (issue 14: --scale 1e-6 ran out of memory).
  // The swatch's box sides, thinnest (its thickness: the shell height at scale 1) first.
  Vector3d swatch_sides = bounding_box(swatch_mesh.V, swatch_mesh.F).extent();
  std::sort(swatch_sides.data(), swatch_sides.data() + 3);
  {
    // The refined base below has the same bounding box, so this is the scale used throughout.
    job.swatch_scale =
        options.element_size > 0
            ? options.element_size / std::max(longer_footprint_side(swatch_mesh), 1e-300)
            : swatch_scale_for(job.cleaned, swatch_mesh, options.scale);
    const double k = job.swatch_scale;
    const double footprint = std::max(swatch_sides(1) * swatch_sides(2), 1e-300) * k * k;
    const double faces = static_cast<double>(swatch_mesh.num_faces()) *
                         face_areas(base_in.V, base_in.F).sum() / footprint;
    stats.estimated_faces = faces;
    MQ_CHECK(faces <= options.max_faces, InvalidInput, "at ", size_option(options),
             " the texture would have about ", faces, " faces, more than the limit of ",
             options.max_faces,
             " (--max-faces, or --max-memory at 400 bytes a face); use a "
             "larger ",
             options.element_size > 0 ? "--element-size" : "--scale");
  }
  // Patches are grown from, and coverage is marked on, whole triangles, so triangles must be
  // small next to the swatch: the base is refined by longest-edge bisection (the surface itself
  // is unchanged) until no edge is longer than base_edge_fraction of the swatch's longer side.
  const double diagonal = bounding_box(base_in.V, base_in.F).extent().norm();
  const double max_edge =
      (options.element_size > 0 ? options.element_size : options.scale * diagonal) *
      options.base_edge_fraction;
  // A base far finer than the texture costs the patches and the shell map in proportion to
  // its faces, not to its surface (issue 14: 354 s for a 1.1M-face bunny that is the 70k one
  // split twice): simplified to the refinement's edge length within a twentieth of the shell
  // height, the texture lies on a surface no farther from the one given than that.
  if (options.proxy_min_faces > 0 && job.cleaned.num_faces() > options.proxy_min_faces) {
    QuadricSimplificationOptions so;
    so.max_error = options.proxy_error * swatch_sides(0) * job.swatch_scale;
    so.max_edge_length = max_edge;
    QuadricSimplification proxy = simplify_by_quadrics(job.cleaned, so);
    if (proxy.mesh.num_faces() < job.cleaned.num_faces()) {
      for (int& f : proxy.origin_face) f = input_face[static_cast<size_t>(f)];
      input_face = std::move(proxy.origin_face);
      job.cleaned = std::move(proxy.mesh);
      job.input_vertex.clear();
      stats.proxy_faces = job.cleaned.num_faces();
      stats.proxy_error = proxy.max_error;
    }
  }
  job.base = bisect_longest_edges(job.cleaned, max_edge, 2'000'000, &job.refinement);
  stats.base_faces = job.base.num_faces();
  // The field is per input face.
  if (options.field.rows()) {
    job.field.resize(job.base.num_faces(), 3);
    for (int f = 0; f < job.base.num_faces(); ++f)
      job.field.row(f) = options.field.row(
          input_face[static_cast<size_t>(job.refinement.parent[static_cast<size_t>(f)])]);
  } else {
    job.field = smooth_tangent_field(job.base.V, job.base.F);
  }
  job.topo = edge_topology(job.base.F, job.base.num_vertices());
  job.TT = face_adjacency(job.topo);
  // The swatch at its size on the surface (section 3.1's relative size s).
  job.swatch = swatch_mesh;
  job.swatch.V *= job.swatch_scale;
  if (options.full_detail_swatch) {
    job.full_swatch = *options.full_detail_swatch;
    job.full_swatch.V *= job.swatch_scale;
  }
  stats.swatch_scale = job.swatch_scale;
  return job;
}

const PreparedSwatch& swatch_at_full_detail(const SurfaceJob& job, const PreparedSwatch& swatch,
                                            PreparedSwatch& storage) {
  if (job.full_swatch.empty()) return swatch;
  storage = prepare_swatch(job.full_swatch);
  return storage;
}

SurfaceQuilt quilt_surface(const TriMesh& base_in, const TriMesh& swatch_mesh,
                           const SurfaceQuiltingOptions& options,
                           TranslationCostEvaluator& evaluator, SurfaceQuiltingStats* stats_out,
                           ProgressSink* progress) {
  SurfaceQuiltingStats stats;
  SurfaceJob job = prepare_surface_job(base_in, swatch_mesh, options, stats);
  return quilt_prepared_surface(std::move(job), std::move(stats), options, evaluator, stats_out,
                                progress);
}

SurfaceQuilt quilt_prepared_surface(SurfaceJob job, SurfaceQuiltingStats stats,
                                    const SurfaceQuiltingOptions& options,
                                    TranslationCostEvaluator& evaluator,
                                    SurfaceQuiltingStats* stats_out, ProgressSink* progress) {
  StageTimes& times = stats.times;
  TriMesh& cleaned = job.cleaned;
  const TriMesh& base = job.base;
  Refinement& refinement = job.refinement;
  const MatrixX3d& field = job.field;
  const EdgeTopology& topo = job.topo;
  const MatrixX3i& TT = job.TT;
  const int nf = base.num_faces();

  PreparedSwatch swatch;
  std::unique_ptr<SwatchFaceTree> swatch_tree;
  const EmbreeDevice embree;  // one device for every BVH of the run
  LaplacianTopologyCache laplacians;
  {
    ScopedStageTimer timer(times, "prepare");
    swatch = prepare_swatch(job.swatch);
    swatch_tree = std::make_unique<SwatchFaceTree>(swatch.mesh.V, swatch.mesh.F);
    laplacians = swatch_topologies(swatch);
  }
  const SwatchQueries queries{*swatch_tree, embree, laplacians};
  const double H = swatch.size.z();
  stats.shell_height = H;
  const double cell = matching_cell_size(swatch);
  stats.cell_size = cell;
  const int swatch_cells =
      static_cast<int>(std::floor(std::min(swatch.size.x(), swatch.size.y()) / cell + 1e-9));
  const int window = std::max(
      1, std::min(swatch_cells, static_cast<int>(options.subpatch_fraction * swatch_cells)));
  const double footprint_area = swatch.size.x() * swatch.size.y();
  // Faces are marked synthesised only this far inside both the swatch and the patch, so that
  // elements cut off at the patch border are grown again by a later patch.
  double max_element = 0;
  for (const Element& e : swatch.elements)
    max_element = std::max(max_element, e.footprint_diameter());
  const double margin =
      std::min(0.5 * max_element, 0.25 * std::min(swatch.size.x(), swatch.size.y()));

  LocalPatchBuilder builder(base, topo, TT);
  SurfaceStore store(nf);
  std::vector<unsigned char> done(nf, 0);
  std::vector<int> count(nf, 0);
  std::set<std::pair<int, int>> queue;  // (-synthesised neighbours, face)
  for (int f = 0; f < nf; ++f) queue.emplace(0, f);
  int num_done = 0;
  auto mark = [&](int f) {
    if (done[f]) return;
    done[f] = 1;
    ++num_done;
    queue.erase({-count[f], f});
    for (int k = 0; k < 3; ++k) {
      const int g = TT(f, k);
      if (g < 0 || done[g]) continue;
      queue.erase({-count[g], g});
      ++count[g];
      queue.emplace(-count[g], g);
    }
  };
  std::mt19937_64 rng(options.seed);
  LocalPatchOptions patch_options;
  {
    // Automatic size: a disk whose radius reaches the farthest swatch corner of any admissible
    // placement (the sub-patch window around the seed stays inside the swatch), so that the
    // swatch lands on the patch wherever matching puts it; elements beyond the patch cannot be
    // stored and are rejected.
    const double half = 0.5 * window * cell;
    const double reach = Vector2d(swatch.size.x() - half, swatch.size.y() - half).norm();
    patch_options.max_area = options.patch_area_factor > 0
                                 ? options.patch_area_factor * footprint_area
                                 : 3.14159265358979 * reach * reach;
  }
  patch_options.max_distortion = options.max_distortion;
  const MatrixX3d base_normals = vertex_normals(base.V, base.F);
  const ClosestPointQuery base_query(embree, base.V, base.F);

  while (!queue.empty()) {
    const int seed = queue.begin()->second;
    ++stats.iterations;
    std::unique_ptr<PatchFrame> frame;
    {
      ScopedStageTimer timer(times, "parameterization");
      LocalPatch patch;
      try {
        patch = builder.grow(seed, patch_options);
      } catch (const InvalidInput&) {
        mark(seed);  // a degenerate triangle: nothing can be placed on it
        continue;
      }
      if (patch.shrink_steps > 0) ++stats.patches_shrunk;
      stats.patch_faces += static_cast<long long>(patch.faces.size());
      frame =
          std::make_unique<PatchFrame>(base, std::move(patch), field.row(seed).transpose(), embree);
    }
    const LocalPatch& patch = frame->patch();

    // The output near the patch, flattened into the frame.
    std::map<int, Element> flat;
    {
      ScopedStageTimer timer(times, "parameterization");
      std::set<int> ids;
      for (const int f : patch.faces)
        for (const int id : store.by_face[f])
          if (store.alive[id]) ids.insert(id);
      for (const int id : ids) {
        const SurfaceElement& s = store.elements[id];
        Element e;
        e.F = s.F;
        e.kind = s.kind;
        e.V.resize(static_cast<Eigen::Index>(s.face.size()), 3);
        for (size_t v = 0; v < s.face.size(); ++v) {
          const Vector2d q = frame->to_frame(s.face[v], s.barycentric.row(v).transpose());
          e.V.row(v) << q.x(), q.y(), s.height(v);
        }
        e.update();
        flat.emplace(id, std::move(e));
      }
    }
    // Whether a frame point lies over a face synthesised before this patch.
    auto processed = [&frame, &done](double x, double y) {
      int f;
      Vector3d b;
      if (!frame->locate(Vector2d(x, y), f, b)) return false;
      return done[frame->patch().faces[f]] != 0;
    };

    // Step 2: geometry matching around the seed (the frame origin).
    OffsetChoice choice;
    {
      ScopedStageTimer timer(times, "matching");
      const double half = 0.5 * window * cell;
      std::vector<const Element*> near;
      near.reserve(flat.size());
      for (const auto& [id, e] : flat) near.push_back(&e);
      MatrixX3d P, NP;
      // Seeds lie just beyond the synthesised surface (faces within 1.5 shell heights of
      // geometry count as synthesised), so the sub-patch reaches half an element (at most three
      // shell heights: long vines would pull in the whole patch) further than the window the
      // swatch must cover: without that it would often hold no output at all and the swatch
      // would be placed unmatched.
      const double reach = half + std::min(0.5 * max_element, 3.0 * H);
      gather_subpatch(near, Vector2d::Constant(-reach), Vector2d::Constant(reach),
                      options.match_points, P, NP);
      const Vector2d t_min = Vector2d::Constant(half) - swatch.size.head<2>();
      const Vector2d t_max = Vector2d::Constant(-half);
      MatrixX3d T = whole_cell_offsets(t_min, t_max, cell);
      MatchingOptions matching = options.matching;
      matching.lambda = options.matching.lambda / cell;
      // The first patch has nothing to match: the swatch is centred on the seed.
      if (P.rows() == 0)
        T = Vector3d(-0.5 * swatch.size.x(), -0.5 * swatch.size.y(), 0).transpose();
      choice = choose_offset(*swatch_tree, evaluator, P, NP, T, t_min, t_max, cell, matching, rng);
      stats.matched_point_offsets += choice.point_offsets;
    }
    const Vector3d t = choice.offset;
    const Vector2d patch_lo = t.head<2>(), patch_hi = patch_lo + swatch.size.head<2>();
    const OverlapRegion region(patch_lo, patch_hi, processed);

    // Steps 3-5 in the frame. A swatch element enters only if it lies wholly on the patch, so
    // that it can be stored in local coordinates.
    FramedOutput framed(store, std::move(flat));
    int outside = 0;
    const std::function<bool(const Element&)> admissible = [&](const Element& e) {
      int f;
      Vector3d b;
      for (int v = 0; v < e.V.rows(); ++v)
        if (!frame->locate(Vector2d(e.V(v, 0), e.V(v, 1)), f, b)) {
          ++outside;
          return false;
        }
      return true;
    };
    PatchCounts counts;
    std::vector<int> rejected;
    quilt_patch(framed, swatch, queries, t, region, admissible, options.patch, counts, times,
                &rejected);
    accumulate(stats.counts, counts);
    stats.rejected_outside_patch += outside;

    // New and changed elements back to local coordinates.
    {
      ScopedStageTimer timer(times, "parameterization");
      for (const int id : framed.changed()) {
        if (!store.alive[id]) continue;
        const Element& e = framed.frame_element(id);
        SurfaceElement s;
        s.F = e.F;
        s.kind = e.kind;
        s.face.resize(e.V.rows());
        s.barycentric.resize(e.V.rows(), 3);
        s.height.resize(e.V.rows());
        for (int v = 0; v < e.V.rows(); ++v) {
          int f;
          Vector3d b;
          const bool in = frame->locate(Vector2d(e.V(v, 0), e.V(v, 1)), f, b);
          if (in) {
            s.face[v] = patch.faces[f];
            s.barycentric.row(v) = b.cwiseMax(0.0).transpose() / b.cwiseMax(0.0).sum();
          } else {
            // Beyond the patch (a changed element reaching out of it): extrapolate the nearest
            // patch face's map into 3D and project onto the base.
            const MatrixX3i& PF = patch.mesh.F;
            const Vector3d p = b(0) * patch.mesh.V.row(PF(f, 0)).transpose() +
                               b(1) * patch.mesh.V.row(PF(f, 1)).transpose() +
                               b(2) * patch.mesh.V.row(PF(f, 2)).transpose();
            const ClosestPointHit hit = base_query.closest(p);
            s.face[v] = hit.face;
            s.barycentric.row(v) = hit.barycentric.transpose();
          }
          s.height(v) = std::clamp(e.V(v, 2), 0.0, H);
        }
        store.elements[id] = std::move(s);
        store.index(id);
      }
    }
    // Mark the patch faces now covered: within 1.5 shell heights of output geometry (issue 4's
    // coverage criterion), whichever patch placed it, or inside the swatch footprint, away from
    // the patch border by the margin (elements there may have been cut off) and away from the
    // swatch elements refused here. Those are the places a later patch must try again; a gap of
    // the swatch itself is a gap of the texture. Elements that would reach into the footprint
    // from outside are missing from every swatch; a later patch seeded beyond the footprint
    // adds them, since they lie partly outside the processed region. (Marking only the
    // footprint's central quarter left ~15 faces of every 16 in a patch to later patches: on
    // the ivy wall half of the patches added nothing.)
    PointsNear2D geometry(1.5 * H);
    for (const int id : framed.elements_near(frame->uv().colwise().minCoeff().transpose(),
                                             frame->uv().colwise().maxCoeff().transpose())) {
      const Element& e = framed.element(id);
      for (int v = 0; v < e.V.rows(); ++v) geometry.add(Vector2d(e.V(v, 0), e.V(v, 1)));
    }
    PointsNear2D refused(std::max(1.5 * H, cell));
    for (const int i : rejected) {
      const Element& e = swatch.elements[static_cast<size_t>(i)];
      for (int v = 0; v < e.V.rows(); ++v)
        refused.add(Vector2d(e.V(v, 0) + t.x(), e.V(v, 1) + t.y()));
    }
    for (size_t f = 0; f < patch.faces.size(); ++f) {
      const Vector2d q = frame->face_centroid(static_cast<int>(f));
      if (geometry.any_within(q) ||
          (q.x() >= patch_lo.x() && q.y() >= patch_lo.y() && q.x() <= patch_hi.x() &&
           q.y() <= patch_hi.y() && frame->distance_to_border(q) >= margin &&
           !refused.any_within(q)))
        mark(patch.faces[f]);
    }
    // A patch that added nothing found a hole no swatch element fits into: give up on the
    // faces around its seed, within half an element, instead of retrying them one by one.
    if (counts.added + counts.replaced + counts.stitched == 0) {
      for (size_t f = 0; f < patch.faces.size(); ++f) {
        if (frame->face_centroid(static_cast<int>(f)).norm() <= 0.5 * max_element)
          mark(patch.faces[f]);
      }
    }
    mark(seed);  // progress is guaranteed
    report_progress(progress, "quilting", num_done, nf);
  }

  SurfaceQuilt quilt;
  quilt.kinds = swatch.kinds;
  quilt.shell_height = H;
  quilt.base = base;
  quilt.input_base = std::move(cleaned);
  quilt.refinement = std::move(refinement);
  quilt.input_vertex = std::move(job.input_vertex);
  {
    ScopedStageTimer timer(times, "post-processing");
    for (size_t id = 0; id < store.elements.size(); ++id)
      if (store.alive[id] && !store.elements[id].face.empty())
        quilt.elements.push_back(std::move(store.elements[id]));
  }
  report_progress(progress, "quilting", 1, 1);
  stats.elements = static_cast<int>(quilt.elements.size());
  for (const SurfaceElement& e : quilt.elements) {
    stats.faces += static_cast<int>(e.F.rows());
    stats.vertices += static_cast<int>(e.face.size());
  }
  if (stats_out) *stats_out = std::move(stats);
  return quilt;
}

}  // namespace mq
