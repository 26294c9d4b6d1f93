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
#include "core/surface/patch_frame.h"
#include "core/surface/points_near_2d.h"
#include "core/surface/surface_store.h"
#include "core/surface/synthesis_front.h"
#include "core/surface/tangent_field.h"

namespace mq {

namespace {

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
  // Faces of no area (vertices on a line) leave no surface to grow on; the first step to
  // notice was the direction field's solve, failing in its own words (issue 26).
  const double area = face_areas(base.V, base.F).sum();
  MQ_CHECK(area > 1e-12 * extent.squaredNorm(), InvalidInput,
           "the base mesh has no area (its faces are flat to lines or points)");
}

// The mesh with only the given faces, in that order, and all its vertices as they are.
TriMesh with_faces(const TriMesh& mesh, const std::vector<int>& faces) {
  TriMesh out;
  out.V = mesh.V;
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t i = 0; i < faces.size(); ++i)
    out.F.row(static_cast<Eigen::Index>(i)) = mesh.F.row(faces[i]);
  return out;
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
  return with_faces(mesh, input_face);
}

// The mesh without the backs of a two-sided sheet: a base whose every face is listed again
// facing the other way encloses nothing, and a shell grown from both sides of it passes through
// itself (a square listed with both orientations placed no element, the message blaming the
// scale). The first listed of each pair stays. A base with faces that have no back keeps all
// its pairs: the wicker chair's 35 (above) lie in components that are two-sided throughout,
// and without their backs the patches' parameterisation meets non-manifold borders there.
// input_face is composed with the change.
//   mesh  without repeated faces (without_duplicate_faces), so a face has at most one back
TriMesh without_sheet_backs(const TriMesh& mesh, std::vector<int>& input_face, int* removed) {
  *removed = 0;
  const int nf = static_cast<int>(mesh.F.rows());
  // Key: the face's vertices sorted, then the face: a face and its back are neighbours.
  std::vector<std::array<int, 4>> sorted(static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    std::array<int, 3> v = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    std::sort(v.begin(), v.end());
    sorted[static_cast<size_t>(f)] = {v[0], v[1], v[2], f};
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> back(static_cast<size_t>(nf), -1);
  for (size_t i = 1; i < sorted.size(); ++i)
    if (std::equal(sorted[i].begin(), sorted[i].begin() + 3, sorted[i - 1].begin())) {
      back[static_cast<size_t>(sorted[i][3])] = sorted[i - 1][3];
      back[static_cast<size_t>(sorted[i - 1][3])] = sorted[i][3];
    }
  if (nf == 0 || std::find(back.begin(), back.end(), -1) != back.end()) return mesh;
  std::vector<int> kept;
  for (int f = 0; f < nf; ++f)
    if (back[static_cast<size_t>(f)] > f) kept.push_back(f);
  *removed = nf - static_cast<int>(kept.size());
  std::vector<int> composed(kept.size());
  for (size_t i = 0; i < kept.size(); ++i) composed[i] = input_face[static_cast<size_t>(kept[i])];
  input_face = std::move(composed);
  return with_faces(mesh, kept);
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

void take_input_bases(SurfaceJob& job, SurfaceQuilt& quilt) {
  quilt.sized = job.log_size.size() > 0;
  quilt.input_base = std::move(job.cleaned);
  quilt.refinement = std::move(job.refinement);
  quilt.input_vertex = std::move(job.input_vertex);
  quilt.welded_base = std::move(job.welded);
  quilt.welded_input_vertex = std::move(job.welded_input_vertex);
}

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

namespace {

// The options prepare_surface_job uses, checked where they enter, in the user's terms.
void validate_surface_options(const SurfaceQuiltingOptions& options, const TriMesh& base_in) {
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
  const Eigen::VectorXd& size = options.size_map;
  if (size.size() == 0) return;
  MQ_CHECK(size.size() == base_in.num_vertices(), InvalidInput, "the size map has ", size.size(),
           " values for ", base_in.num_vertices(), " base vertices");
  MQ_CHECK(size.allFinite() && size.minCoeff() > 0, InvalidInput,
           "the size map's values must be positive and finite");
  MQ_CHECK(size.maxCoeff() <= SurfaceQuiltingOptions::kMaxSizeMapRange * size.minCoeff(),
           InvalidInput, "the size map's largest value is ", size.maxCoeff() / size.minCoeff(),
           " times its smallest, more than ", SurfaceQuiltingOptions::kMaxSizeMapRange,
           " (neighbouring elements of sizes so far apart cannot keep their links)");
}

// job.cleaned and job.input_vertex from the base as given; returns, per face of job.cleaned,
// the face of base_in it is.
std::vector<int> clean_base(const TriMesh& base_in, const SurfaceQuiltingOptions& options,
                            SurfaceJob& job, SurfaceQuiltingStats& stats) {
  // Exporters split vertices along hard edges; welded, a box's sides form one surface and
  // patches (and elements) can wrap around its edges.
  job.cleaned = weld_vertices(base_in, &stats.welded_vertices, &job.input_vertex);
  std::vector<int> input_face;  // job.cleaned's faces -> base_in's
  job.cleaned = without_duplicate_faces(job.cleaned, input_face, &stats.duplicate_faces);
  job.cleaned = without_sheet_backs(job.cleaned, input_face, &stats.sheet_back_faces);
  job.cleaned = without_fins(job.cleaned, input_face, job.input_vertex, stats);
  // The shell grows along the normal: components turned inside out would hide the texture
  // inside the object.
  if (options.orient_outward) stats.flipped_components = orient_outward(job.cleaned);
  return input_face;
}

// The base's area, each face's weighted by the mean over its corners of 1 / size^2 when a size
// map is given (elements of half the size are four times as many).
double size_weighted_area(const TriMesh& base_in, const Eigen::VectorXd& size_map) {
  const Eigen::VectorXd area = face_areas(base_in.V, base_in.F);
  if (size_map.size() == 0) return area.sum();
  double sum = 0;
  for (int f = 0; f < base_in.num_faces(); ++f) {
    double w = 0;
    for (int k = 0; k < 3; ++k) w += 1 / (size_map(base_in.F(f, k)) * size_map(base_in.F(f, k)));
    sum += area(f) * w / 3;
  }
  return sum;
}

// The swatch's scale on the surface (section 3.1's relative size s), and the output estimated
// before any work: the swatch's faces per unit of footprint area at that scale, over the base's
// area (issue 14: --scale 1e-6 ran out of memory). Throws InvalidInput over options.max_faces.
//   swatch_sides  the swatch's box sides, thinnest (its thickness) first
void scale_within_estimate(const TriMesh& base_in, const TriMesh& swatch_mesh,
                           const Vector3d& swatch_sides, const SurfaceQuiltingOptions& options,
                           SurfaceJob& job, SurfaceQuiltingStats& stats) {
  // The refined base has the same bounding box, so this is the scale used throughout.
  job.swatch_scale =
      options.element_size > 0
          ? options.element_size / std::max(longer_footprint_side(swatch_mesh), 1e-300)
          : swatch_scale_for(job.cleaned, swatch_mesh, options.scale);
  const double k = job.swatch_scale;
  const double footprint = std::max(swatch_sides(1) * swatch_sides(2), 1e-300) * k * k;
  const double faces = static_cast<double>(swatch_mesh.num_faces()) *
                       size_weighted_area(base_in, options.size_map) / footprint;
  stats.estimated_faces = faces;
  // The swatch (and so the shell) at the largest size the map asks for; smaller elements are
  // made smaller copies (SurfaceJob::log_size is relative to it).
  if (options.size_map.size()) job.swatch_scale *= options.size_map.maxCoeff();
  MQ_CHECK(faces <= options.max_faces, InvalidInput, "at ", size_option(options),
           " the texture would have about ", faces, " faces, more than the limit of ",
           options.max_faces,
           " (--max-faces, or --max-memory at 400 bytes a face); use a "
           "larger ",
           options.element_size > 0 ? "--element-size" : "--scale");
}

// A base far finer than the texture costs the patches and the shell map in proportion to its
// faces, not to its surface (issue 14: 354 s for a 1.1M-face bunny that is the 70k one split
// twice): simplified to the refinement's edge length within a twentieth of the shell height, the
// texture lies on a surface no farther from the one given than that.
void simplify_to_proxy(const SurfaceQuiltingOptions& options, double thickness, double max_edge,
                       SurfaceJob& job, std::vector<int>& input_face, SurfaceQuiltingStats& stats) {
  if (options.proxy_min_faces <= 0 || job.cleaned.num_faces() <= options.proxy_min_faces) return;
  QuadricSimplificationOptions so;
  so.max_error = options.proxy_error * thickness * job.swatch_scale;
  so.max_edge_length = max_edge;
  QuadricSimplification proxy = simplify_by_quadrics(job.cleaned, so);
  if (proxy.mesh.num_faces() >= job.cleaned.num_faces()) return;
  for (int& f : proxy.origin_face) f = input_face[static_cast<size_t>(f)];
  input_face = std::move(proxy.origin_face);
  job.welded = std::move(job.cleaned);
  job.welded_input_vertex = std::move(job.input_vertex);
  job.cleaned = std::move(proxy.mesh);
  job.input_vertex.clear();
  stats.proxy_faces = job.cleaned.num_faces();
  stats.proxy_error = proxy.max_error;
}

// The log of the size map over its largest value at each vertex of job.base
// (SurfaceJob::log_size: relative to the swatch, which is at the largest size): through each
// refined face's corners in its parent face, whose corners are those of the input face it came from
// (welding and removing faces keep the corners' order); under a proxy, whose faces are not
// input faces, the mean over a vertex's faces of their origin faces' mean log size.
Eigen::VectorXd refined_log_size(const TriMesh& base_in, const Eigen::VectorXd& size_map,
                                 const std::vector<int>& input_face, const SurfaceJob& job) {
  const Eigen::VectorXd log_in = (size_map / size_map.maxCoeff()).array().log();
  const int nv = job.base.num_vertices();
  Eigen::VectorXd out = Eigen::VectorXd::Zero(nv);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(nv);
  const bool proxy = job.input_vertex.empty();
  for (int f = 0; f < job.base.num_faces(); ++f) {
    const int parent = job.refinement.parent[static_cast<size_t>(f)];
    const int in = input_face[static_cast<size_t>(parent)];
    const Vector3d corner_log(log_in(base_in.F(in, 0)), log_in(base_in.F(in, 1)),
                              log_in(base_in.F(in, 2)));
    for (int k = 0; k < 3; ++k) {
      const int v = job.base.F(f, k);
      const Vector3d b = job.refinement.corners.row(f).segment<3>(3 * k).transpose();
      out(v) += proxy ? corner_log.mean() : b.dot(corner_log);
      count(v) += 1;
    }
  }
  return out.cwiseQuotient(count.cwiseMax(1.0));
}

// Patches are grown from, and coverage is marked on, whole triangles, so triangles must be
// small next to the swatch: the base is refined by longest-edge bisection (the surface itself
// is unchanged) until no edge is longer than max_edge; the guidance field (given per input
// face, or the smooth default) and the adjacency over the refined faces.
void refine_base(const TriMesh& base_in, const SurfaceQuiltingOptions& options, double max_edge,
                 const std::vector<int>& input_face, SurfaceJob& job, SurfaceQuiltingStats& stats) {
  job.base = bisect_longest_edges(job.cleaned, max_edge, 2'000'000, &job.refinement);
  stats.base_faces = job.base.num_faces();
  if (options.field.rows()) {
    job.field.resize(job.base.num_faces(), 3);
    for (int f = 0; f < job.base.num_faces(); ++f)
      job.field.row(f) = options.field.row(
          input_face[static_cast<size_t>(job.refinement.parent[static_cast<size_t>(f)])]);
  } else {
    job.field = smooth_tangent_field(job.base.V, job.base.F);
  }
  if (options.size_map.size())
    job.log_size = refined_log_size(base_in, options.size_map, input_face, job);
  job.topo = edge_topology(job.base.F, job.base.num_vertices());
  job.TT = face_adjacency(job.topo);
}

}  // namespace

SurfaceJob prepare_surface_job(const TriMesh& base_in, const TriMesh& swatch_mesh,
                               const SurfaceQuiltingOptions& options, SurfaceQuiltingStats& stats) {
  validate_base(base_in);
  validate_surface_options(options, base_in);
  ScopedStageTimer timer(stats.times, Stage::Prepare);
  SurfaceJob job;
  std::vector<int> input_face = clean_base(base_in, options, job, stats);
  Vector3d swatch_sides = bounding_box(swatch_mesh.V, swatch_mesh.F).extent();
  std::sort(swatch_sides.data(), swatch_sides.data() + 3);
  scale_within_estimate(base_in, swatch_mesh, swatch_sides, options, job, stats);
  const double diagonal = bounding_box(base_in.V, base_in.F).extent().norm();
  double max_edge = (options.element_size > 0 ? options.element_size : options.scale * diagonal) *
                    options.base_edge_fraction;
  // Refined for the smallest elements the size map asks for.
  if (options.size_map.size()) max_edge *= std::min(1.0, options.size_map.minCoeff());
  simplify_to_proxy(options, swatch_sides(0), max_edge, job, input_face, stats);
  refine_base(base_in, options, max_edge, input_face, job, stats);
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

double face_log_size(const SurfaceJob& job, int f) {
  if (job.log_size.size() == 0) return 0.0;
  return (job.log_size(job.base.F(f, 0)) + job.log_size(job.base.F(f, 1)) +
          job.log_size(job.base.F(f, 2))) /
         3;
}

double nominal_size(const SurfaceJob& job, int f) {
  return job.log_size.size() ? std::exp(face_log_size(job, f)) : 1.0;
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

namespace {

// Local-patch synthesis (paper section 3.1) between its steps: the prepared swatch and its
// queries, the output store, the front of synthesised faces. One iteration grows a patch around
// the front's next seed, flattens the output near it into the patch's frame, matches the swatch
// there (section 2.4), runs the planar steps of section 2 in the frame, stores what changed in
// local coordinates and marks the faces now synthesised.
class LocalPatchSynthesis {
 public:
  LocalPatchSynthesis(SurfaceJob& job, const SurfaceQuiltingOptions& options,
                      TranslationCostEvaluator& evaluator, SurfaceQuiltingStats& stats);
  bool finished() const { return front_.empty(); }
  void run_patch(ProgressSink* progress);
  SurfaceQuilt take_quilt(SurfaceJob& job);

 private:
  std::unique_ptr<PatchFrame> grow_patch(int seed);
  std::map<int, Element> flatten_output(const PatchFrame& frame);
  Vector3d match(const std::map<int, Element>& flat);
  void store_changed(const PatchFrame& frame, const FramedOutput& framed);
  void mark_synthesised(int seed, const PatchFrame& frame, const FramedOutput& framed,
                        const Vector3d& t, const std::vector<int>& rejected,
                        const PatchCounts& counts);

  const SurfaceJob& job_;
  const SurfaceQuiltingOptions& options_;
  TranslationCostEvaluator& evaluator_;
  SurfaceQuiltingStats& stats_;
  StageTimes& times_;
  PreparedSwatch swatch_;
  std::unique_ptr<SwatchFaceTree> swatch_tree_;
  const EmbreeDevice embree_;  // one device for every BVH of the run
  LaplacianTopologyCache laplacians_;
  double H_ = 0;              // the shell height
  double cell_ = 0;           // the matching grid's cell (section 2.4)
  int window_ = 1;            // the sub-patch window around the seed, in cells
  double max_element_ = 0;    // the largest element's footprint diameter
  double margin_ = 0;         // faces are marked synthesised this far inside swatch and patch
  double near_geometry_ = 0;  // and this near output geometry
  LocalPatchBuilder builder_;
  LocalPatchOptions patch_options_;
  SurfaceStore store_;
  SynthesisFront front_;
  std::mt19937_64 rng_;
  std::unique_ptr<ClosestPointQuery> base_query_;
};

LocalPatchSynthesis::LocalPatchSynthesis(SurfaceJob& job, const SurfaceQuiltingOptions& options,
                                         TranslationCostEvaluator& evaluator,
                                         SurfaceQuiltingStats& stats)
    : job_(job),
      options_(options),
      evaluator_(evaluator),
      stats_(stats),
      times_(stats.times),
      builder_(job.base, job.topo, job.TT),
      store_(job.base.num_faces()),
      front_(job.TT),
      rng_(options.seed) {
  {
    ScopedStageTimer timer(times_, Stage::Prepare);
    swatch_ = prepare_swatch(job.swatch);
    if (options.keep_sources) track_sources(swatch_);
    swatch_tree_ = std::make_unique<SwatchFaceTree>(swatch_.mesh.V, swatch_.mesh.F);
    laplacians_ = swatch_topologies(swatch_);
  }
  H_ = swatch_.size.z();
  stats_.shell_height = H_;
  cell_ = matching_cell_size(swatch_);
  stats_.cell_size = cell_;
  const int swatch_cells =
      static_cast<int>(std::floor(std::min(swatch_.size.x(), swatch_.size.y()) / cell_ + 1e-9));
  window_ = std::max(
      1, std::min(swatch_cells, static_cast<int>(options.subpatch_fraction * swatch_cells)));
  const double footprint_area = swatch_.size.x() * swatch_.size.y();
  // Faces are marked synthesised only this far inside both the swatch and the patch, so that
  // elements cut off at the patch border are grown again by a later patch.
  for (const Element& e : swatch_.elements)
    max_element_ = std::max(max_element_, e.footprint_diameter());
  margin_ = std::min(0.5 * max_element_, 0.25 * std::min(swatch_.size.x(), swatch_.size.y()));
  // Near geometry counts as covered within 1.5 shell heights (issue 4's coverage criterion), but
  // no farther than about a third of an element: elements as tall as they are wide (apples)
  // made that a band of most of an element around each patch, where no later patch was seeded,
  // and the swatch's own gaps at its border became bare streaks between patches (apples of 11
  // on a flat sheet: 76% of the swatch's density, 87% with the bound, the plane 99%; it takes
  // 1.5-2x the patches). Threads and vines, long elements, keep the shell heights.
  near_geometry_ = std::min(1.5 * H_, 0.35 * max_element_);
  // Automatic size: a disk whose radius reaches the farthest swatch corner of any admissible
  // placement (the sub-patch window around the seed stays inside the swatch), so that the
  // swatch lands on the patch wherever matching puts it; elements beyond the patch cannot be
  // stored and are rejected.
  const double half = 0.5 * window_ * cell_;
  const double reach = Vector2d(swatch_.size.x() - half, swatch_.size.y() - half).norm();
  patch_options_.max_area = options.patch_area_factor > 0
                                ? options.patch_area_factor * footprint_area
                                : 3.14159265358979 * reach * reach;
  patch_options_.max_distortion = options.max_distortion;
  base_query_ = std::make_unique<ClosestPointQuery>(embree_, job.base.V, job.base.F);
}

void LocalPatchSynthesis::run_patch(ProgressSink* progress) {
  const int seed = front_.next();
  ++stats_.iterations;
  const std::unique_ptr<PatchFrame> frame = grow_patch(seed);
  if (!frame) {
    front_.mark(seed);  // a degenerate triangle: nothing can be placed on it
    return;
  }
  std::map<int, Element> flat = flatten_output(*frame);
  const Vector3d t = match(flat);
  // Whether a frame point lies over a face synthesised before this patch.
  const auto synthesised = [this, &frame](double x, double y) {
    int f;
    Vector3d b;
    if (!frame->locate(Vector2d(x, y), f, b)) return false;
    return front_.synthesised(frame->patch().faces[f]);
  };
  const Vector2d patch_lo = t.head<2>(), patch_hi = patch_lo + swatch_.size.head<2>();
  const OverlapRegion region(patch_lo, patch_hi, synthesised);
  // Steps 3-5 in the frame. A swatch element enters only if it lies wholly on the patch, so
  // that it can be stored in local coordinates.
  FramedOutput framed(store_, std::move(flat));
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
  const SwatchQueries queries{*swatch_tree_, embree_, laplacians_};
  PatchCounts counts;
  std::vector<int> rejected;
  quilt_patch(framed, swatch_, queries, t, region, admissible, options_.patch, counts, times_,
              &rejected);
  accumulate(stats_.counts, counts);
  stats_.rejected_outside_patch += outside;
  store_changed(*frame, framed);
  mark_synthesised(seed, *frame, framed, t, rejected, counts);
  report_progress(progress, Stage::Quilting, front_.num_synthesised(), job_.base.num_faces());
}

// The local patch around the seed (core/surface/local_patch), flattened into the frame the
// guidance field orients; null for a degenerate seed triangle.
std::unique_ptr<PatchFrame> LocalPatchSynthesis::grow_patch(int seed) {
  ScopedStageTimer timer(times_, Stage::Parameterization);
  // Under a size map (issue 25) the frame is the surface over the size wanted at the seed: the
  // swatch lands that much smaller, on a patch that much smaller. Sizes vary smoothly, so an
  // element of a neighbouring patch comes into this frame within a few percent of its swatch
  // element's size, like the conformal map's own distortion.
  const double size = nominal_size(job_, seed);
  LocalPatchOptions patch_options = patch_options_;
  patch_options.max_area *= size * size;
  LocalPatch patch;
  try {
    patch = builder_.grow(seed, patch_options);
  } catch (const InvalidInput&) {
    return nullptr;
  }
  if (patch.shrink_steps > 0) ++stats_.patches_shrunk;
  stats_.patch_faces += static_cast<long long>(patch.faces.size());
  return std::make_unique<PatchFrame>(job_.base, std::move(patch), job_.field.row(seed).transpose(),
                                      embree_, size);
}

// The output near the patch, flattened into the frame, by id.
std::map<int, Element> LocalPatchSynthesis::flatten_output(const PatchFrame& frame) {
  ScopedStageTimer timer(times_, Stage::Parameterization);
  std::map<int, Element> flat;
  std::set<int> ids;
  for (const int f : frame.patch().faces)
    for (const int id : store_.by_face[f])
      if (store_.alive[id]) ids.insert(id);
  for (const int id : ids) {
    const SurfaceElement& s = store_.elements[id];
    Element e;
    e.F = s.F;
    e.kind = s.kind;
    e.source = s.source;
    e.source_element = s.source_element;
    e.V.resize(static_cast<Eigen::Index>(s.face.size()), 3);
    for (size_t v = 0; v < s.face.size(); ++v) {
      const Vector2d q = frame.to_frame(s.face[v], s.barycentric.row(v).transpose());
      e.V.row(v) << q.x(), q.y(), s.height(v) / frame.size();
    }
    e.update();
    flat.emplace(id, std::move(e));
  }
  return flat;
}

// Step 2: geometry matching around the seed (the frame origin); the swatch's offset.
Vector3d LocalPatchSynthesis::match(const std::map<int, Element>& flat) {
  ScopedStageTimer timer(times_, Stage::Matching);
  const double half = 0.5 * window_ * cell_;
  std::vector<const Element*> near;
  near.reserve(flat.size());
  for (const auto& [id, e] : flat) near.push_back(&e);
  MatrixX3d P, NP;
  // Seeds lie just beyond the synthesised surface (faces within near_geometry_ of geometry
  // count as synthesised), so the sub-patch reaches half an element (at most three shell
  // heights: long vines would pull in the whole patch) further than the window the swatch must
  // cover: without that it would often hold no output at all and the swatch would be placed
  // unmatched.
  const double reach = half + std::min(0.5 * max_element_, 3.0 * H_);
  gather_subpatch(near, Vector2d::Constant(-reach), Vector2d::Constant(reach),
                  options_.match_points, P, NP);
  const Vector2d t_min = Vector2d::Constant(half) - swatch_.size.head<2>();
  const Vector2d t_max = Vector2d::Constant(-half);
  MatrixX3d T = whole_cell_offsets(t_min, t_max, cell_);
  MatchingOptions matching = options_.matching;
  matching.lambda = options_.matching.lambda / cell_;
  // The first patch has nothing to match: the swatch is centred on the seed.
  if (P.rows() == 0) T = Vector3d(-0.5 * swatch_.size.x(), -0.5 * swatch_.size.y(), 0).transpose();
  const OffsetChoice choice =
      choose_offset(*swatch_tree_, evaluator_, P, NP, T, t_min, t_max, cell_, matching, rng_);
  stats_.matched_point_offsets += choice.point_offsets;
  return choice.offset;
}

// New and changed elements back to local coordinates.
void LocalPatchSynthesis::store_changed(const PatchFrame& frame, const FramedOutput& framed) {
  ScopedStageTimer timer(times_, Stage::Parameterization);
  const LocalPatch& patch = frame.patch();
  for (const int id : framed.changed()) {
    if (!store_.alive[id]) continue;
    const Element& e = framed.frame_element(id);
    SurfaceElement s;
    s.F = e.F;
    s.kind = e.kind;
    s.source = e.source;
    s.source_element = e.source_element;
    s.face.resize(e.V.rows());
    s.barycentric.resize(e.V.rows(), 3);
    s.height.resize(e.V.rows());
    for (int v = 0; v < e.V.rows(); ++v) {
      int f;
      Vector3d b;
      const bool in = frame.locate(Vector2d(e.V(v, 0), e.V(v, 1)), f, b);
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
        const ClosestPointHit hit = base_query_->closest(p);
        s.face[v] = hit.face;
        s.barycentric.row(v) = hit.barycentric.transpose();
      }
      s.height(v) = std::clamp(e.V(v, 2), 0.0, H_) * frame.size();
    }
    store_.elements[id] = std::move(s);
    store_.index(id);
  }
}

// Marks the patch faces now synthesised: near output geometry (within near_geometry_),
// whichever patch placed it, or inside the swatch footprint, away from the
// patch border by the margin (elements there may have been cut off) and away from the swatch
// elements refused here. Those are the places a later patch must try again; a gap of the swatch
// itself is a gap of the texture. Elements that would reach into the footprint from outside are
// missing from every swatch; a later patch seeded beyond the footprint adds them, since they lie
// partly outside the synthesised region. (Marking only the footprint's central quarter left ~15
// faces of every 16 in a patch to later patches: on the ivy wall half of the patches added
// nothing.)
void LocalPatchSynthesis::mark_synthesised(int seed, const PatchFrame& frame,
                                           const FramedOutput& framed, const Vector3d& t,
                                           const std::vector<int>& rejected,
                                           const PatchCounts& counts) {
  const LocalPatch& patch = frame.patch();
  const Vector2d patch_lo = t.head<2>(), patch_hi = patch_lo + swatch_.size.head<2>();
  PointsNear2D geometry(near_geometry_);
  for (const int id : framed.elements_near(frame.uv().colwise().minCoeff().transpose(),
                                           frame.uv().colwise().maxCoeff().transpose())) {
    const Element& e = framed.element(id);
    for (int v = 0; v < e.V.rows(); ++v) geometry.add(Vector2d(e.V(v, 0), e.V(v, 1)));
  }
  PointsNear2D refused(std::max(1.5 * H_, cell_));
  for (const int i : rejected) {
    const Element& e = swatch_.elements[static_cast<size_t>(i)];
    for (int v = 0; v < e.V.rows(); ++v)
      refused.add(Vector2d(e.V(v, 0) + t.x(), e.V(v, 1) + t.y()));
  }
  for (size_t f = 0; f < patch.faces.size(); ++f) {
    const Vector2d q = frame.face_centroid(static_cast<int>(f));
    if (geometry.any_within(q) ||
        (q.x() >= patch_lo.x() && q.y() >= patch_lo.y() && q.x() <= patch_hi.x() &&
         q.y() <= patch_hi.y() && frame.distance_to_border(q) >= margin_ && !refused.any_within(q)))
      front_.mark(patch.faces[f]);
  }
  // A patch that added nothing found a hole no swatch element fits into: give up on the faces
  // around its seed, within half an element, instead of retrying them one by one.
  if (counts.added + counts.replaced + counts.stitched == 0) {
    for (size_t f = 0; f < patch.faces.size(); ++f) {
      if (frame.face_centroid(static_cast<int>(f)).norm() <= 0.5 * max_element_)
        front_.mark(patch.faces[f]);
    }
  }
  front_.mark(seed);  // progress is guaranteed
}

// The surviving elements, in the order they were made, over the job's bases.
SurfaceQuilt LocalPatchSynthesis::take_quilt(SurfaceJob& job) {
  SurfaceQuilt quilt;
  quilt.kinds = swatch_.kinds;
  quilt.shell_height = H_;
  quilt.stitched = true;
  quilt.base = job.base;
  take_input_bases(job, quilt);
  ScopedStageTimer timer(times_, Stage::PostProcessing);
  for (size_t id = 0; id < store_.elements.size(); ++id)
    if (store_.alive[id] && !store_.elements[id].face.empty())
      quilt.elements.push_back(std::move(store_.elements[id]));
  return quilt;
}

}  // namespace

SurfaceQuilt quilt_prepared_surface(SurfaceJob job, SurfaceQuiltingStats stats,
                                    const SurfaceQuiltingOptions& options,
                                    TranslationCostEvaluator& evaluator,
                                    SurfaceQuiltingStats* stats_out, ProgressSink* progress) {
  LocalPatchSynthesis synthesis(job, options, evaluator, stats);
  while (!synthesis.finished()) synthesis.run_patch(progress);
  SurfaceQuilt quilt = synthesis.take_quilt(job);
  report_progress(progress, Stage::Quilting, 1, 1);
  stats.elements = static_cast<int>(quilt.elements.size());
  for (const SurfaceElement& e : quilt.elements) {
    stats.faces += static_cast<int>(e.F.rows());
    stats.vertices += static_cast<int>(e.face.size());
  }
  if (stats_out) *stats_out = std::move(stats);
  return quilt;
}

}  // namespace mq
