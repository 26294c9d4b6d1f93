#include "core/planar/element_merging.h"

#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/boundary_loops.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/element_cut.h"
#include "core/planar/element_stitch.h"
#include "core/planar/laplacian_deformation.h"

namespace mq {

namespace {

int count_boundary_edges(const MatrixX3i& F, int nv) {
  const EdgeTopology topo = edge_topology(F, nv);
  int n = 0;
  for (int e = 0; e < topo.num_edges(); ++e) n += topo.is_boundary(e);
  return n;
}

Vector3d centroid(const Element& e, int f) {
  return (e.V.row(e.F(f, 0)) + e.V.row(e.F(f, 1)) + e.V.row(e.F(f, 2))).transpose() / 3.0;
}

bool face_outside(const Element& e, int f, const OverlapRegion& region) {
  for (int k = 0; k < 3; ++k)
    if (region.contains(Vector3d(e.V.row(e.F(f, k)).transpose()))) return false;
  return true;
}

// Breadth-first depth of every face from the seed faces over the dual graph (-1: unreached).
std::vector<int> dual_depth(const MatrixX3i& TT, const std::vector<int>& seeds) {
  std::vector<int> depth(TT.rows(), -1), queue = seeds;
  for (const int f : seeds) depth[f] = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int f = queue[head];
    for (int k = 0; k < 3; ++k) {
      const int g = TT(f, k);
      if (g >= 0 && depth[g] < 0) {
        depth[g] = depth[f] + 1;
        queue.push_back(g);
      }
    }
  }
  return depth;
}

// Labels for cutting the output element (section 2.7). SOURCE: faces of the old output outside
// the new patch. SINK: the far end, seen from the SOURCE faces, of the band of faces that the
// swatch element covers: the part the swatch element continues and replaces (a thread's end cap,
// the half of a ring lying over the new patch). The paper marks the faces around vertices whose
// partner face lies at the rim of the matched area; on closed tubes that rim can fall between
// two vertex rings and be missed, while the far end of the covered band is always defined.
//   TT  out's face adjacency (face_adjacency)
std::vector<CutLabel> output_labels(const Element& out, const MatrixX3i& TT,
                                    const ClosestPointQuery& query_in, const OverlapRegion& region,
                                    double cover) {
  const int nf = static_cast<int>(out.F.rows());
  std::vector<CutLabel> hard(nf, CutLabel::Free);
  std::vector<int> source;
  std::vector<char> covered(nf, 0);
  for (int f = 0; f < nf; ++f) {
    // SOURCE is the old output, outside the new patch. Parts of an output element reaching into
    // unprocessed cells of the patch (elements are kept whole, so they protrude) are not: that
    // is where the swatch takes over.
    bool old_region = true;
    for (int k = 0; k < 3; ++k)
      old_region = old_region && !region.in_patch(out.V(out.F(f, k), 0), out.V(out.F(f, k), 1));
    if (old_region) {
      hard[f] = CutLabel::Keep;
      source.push_back(f);
    } else {
      covered[f] = query_in.closest(centroid(out, f), cover).face >= 0;
    }
  }
  const std::vector<int> depth = dual_depth(TT, source);
  int deepest = -1;
  for (int f = 0; f < nf; ++f)
    if (covered[f]) deepest = std::max(deepest, depth[f]);
  if (deepest <= 0) return hard;  // nothing covered beyond the kept part: no SINK
  // The last two layers of the covered band form the SINK.
  for (int f = 0; f < nf; ++f)
    if (covered[f] && depth[f] >= deepest - 1 && hard[f] == CutLabel::Free)
      hard[f] = CutLabel::Remove;
  return hard;
}

// Labels for cutting the swatch element so that its cut complements the output's: a face lying
// on a kept output face is removed (the output already has it), one lying on a removed output
// face is kept (it replaces it) except within two rings of the output's seam, where the min-cut
// closes the loop; faces outside the overlapping region are always kept.
//   TT_out  out's face adjacency (face_adjacency)
std::vector<CutLabel> swatch_labels(const Element& in, const MatrixX3i& TT_out,
                                    const std::vector<bool>& keep_out,
                                    const ClosestPointQuery& query_out, const OverlapRegion& region,
                                    double cover) {
  const int nf = static_cast<int>(in.F.rows());
  // Output faces within two rings of the output's cut are "near the seam".
  std::vector<int> seam;
  for (int f = 0; f < TT_out.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = TT_out(f, k);
      if (g >= 0 && keep_out[f] != keep_out[g]) {
        seam.push_back(f);
        break;
      }
    }
  const std::vector<int> seam_depth = dual_depth(TT_out, seam);
  std::vector<CutLabel> hard(nf, CutLabel::Free);
  for (int g = 0; g < nf; ++g) {
    if (face_outside(in, g, region)) {
      hard[g] = CutLabel::Keep;
      continue;
    }
    const ClosestPointHit hit = query_out.closest(centroid(in, g), cover);
    if (hit.face < 0) continue;
    if (keep_out[hit.face]) {
      hard[g] = CutLabel::Remove;  // the output keeps this part
    } else if (seam_depth[hit.face] < 0 || seam_depth[hit.face] > 2) {
      hard[g] = CutLabel::Keep;  // replaces a removed output part away from the seam
    }
    // else: over the removed side, close to the output's seam: the min-cut closes the loop
    // there, so the two kept parts meet with a small gap and never overlap.
  }
  return hard;
}

// Dist(v, C_other) of Eq. (7) at the vertices of e's faces not labelled Keep, 0 elsewhere: the
// cut reads no other (element_graph_cut), and most of an output thread is Keep.
Eigen::VectorXd distances_off_keep(const Element& e, const std::vector<CutLabel>& labels,
                                   const ClosestPointQuery& other) {
  std::vector<char> needed(e.V.rows(), 0);
  for (int f = 0; f < e.F.rows(); ++f)
    if (labels[f] != CutLabel::Keep)
      for (int k = 0; k < 3; ++k) needed[e.F(f, k)] = 1;
  std::vector<int> vertices;
  for (int v = 0; v < e.V.rows(); ++v)
    if (needed[v]) vertices.push_back(v);
  MatrixX3d points(vertices.size(), 3);
  for (size_t i = 0; i < vertices.size(); ++i) points.row(i) = e.V.row(vertices[i]);
  const std::vector<ClosestPointHit> hits = other.closest(points);
  Eigen::VectorXd dist = Eigen::VectorXd::Zero(e.V.rows());
  for (size_t i = 0; i < vertices.size(); ++i) dist(vertices[i]) = hits[i].distance;
  return dist;
}

// The faces of e that `keep` marks; `vertices`: e's vertex each of the part's is.
TriMesh kept_part(const Element& e, const std::vector<bool>& keep, std::vector<int>& vertices) {
  std::vector<int> faces;
  for (size_t f = 0; f < keep.size(); ++f)
    if (keep[f]) faces.push_back(static_cast<int>(f));
  return extract_faces(e.mesh(), faces, &vertices);
}

}  // namespace

const char* stitch_failure_name(StitchFailure f) {
  switch (f) {
    case StitchFailure::None:
      return "none";
    case StitchFailure::EmptyCut:
      return "empty_cut";
    case StitchFailure::NothingCut:
      return "nothing_cut";
    case StitchFailure::BadSeam:
      return "bad_seam";
    case StitchFailure::LoopsUnpaired:
      return "loops_unpaired";
    case StitchFailure::NotOneComponent:
      return "not_one_component";
    case StitchFailure::OpenSeam:
      return "open_seam";
    case StitchFailure::Distorted:
      return "distorted";
    case StitchFailure::SelfIntersecting:
      return "self_intersecting";
  }
  return "unknown";
}

bool elements_coincide(const Element& a, const Element& b, double tolerance,
                       const EmbreeDevice* device) {
  // Each bounding box lies within the other's enlarged by the tolerance when the elements
  // coincide, so boxes further apart than that rule it out without building a BVH. The
  // margin keeps the shortcut conservative under rounding; the exact test decides the rest.
  const double margin = tolerance * (1 + 1e-9) + 1e-12 * (a.hi - a.lo).norm();
  const auto apart = [&](double x, double y) { return std::abs(x - y) > margin; };
  for (int k = 0; k < 2; ++k)
    if (apart(a.lo[k], b.lo[k]) || apart(a.hi[k], b.hi[k])) return false;
  if (apart(a.z_lo, b.z_lo) || apart(a.z_hi, b.z_hi)) return false;
  const EmbreeDevice shared = device ? *device : EmbreeDevice();
  const auto all_within = [&](const Element& from, const Element& to) {
    const ClosestPointQuery query(shared, to.V, to.F);
    for (const ClosestPointHit& hit : query.closest(from.V, tolerance))
      if (hit.face < 0) return false;
    return true;
  };
  return all_within(a, b) && all_within(b, a);
}

namespace {

// Why the stitched mesh is not one element as closed as its parents and manifold along the
// seam (None when it is). One edge topology answers both seam checks; the parents' open edges
// are counted only when the stitched element has any (closed elements, the common case, never
// need them).
StitchFailure seam_failure(const TriMesh& stitched, const Element& out, const Element& in) {
  std::vector<int> fc;
  if (connected_components(stitched.F, stitched.num_vertices(), fc) != 1)
    return StitchFailure::NotOneComponent;
  const EdgeTopology topo = edge_topology(stitched.F, stitched.num_vertices());
  int boundary = 0, non_manifold = 0;
  for (int e = 0; e < topo.num_edges(); ++e) {
    boundary += topo.is_boundary(e);
    non_manifold += topo.is_non_manifold(e);
  }
  if (boundary > 0 && boundary > count_boundary_edges(out.F, static_cast<int>(out.V.rows())) +
                                     count_boundary_edges(in.F, static_cast<int>(in.V.rows())))
    return StitchFailure::OpenSeam;
  if (non_manifold > 0) return StitchFailure::BadSeam;
  return StitchFailure::None;
}

// Why the deformed merged element is refused (None when it is kept): it must stay within the
// space of its two parents (a wrongly paired seam drags vertices far away) and must not pass
// through itself. The whole element is tested: on a surface the output's own element may already
// pass through itself (the sphere's weave by patches: 5 -> 10 elements removed as
// self-intersecting when only the changed faces were tested).
StitchFailure merged_failure(const Element& result, const Element& out, const Element& in,
                             double mean_edge_length) {
  const double slack = 2.0 * mean_edge_length;
  const Vector2d lo = out.lo.cwiseMin(in.lo).array() - slack;
  const Vector2d hi = out.hi.cwiseMax(in.hi).array() + slack;
  if ((result.lo.array() < lo.array()).any() || (result.hi.array() > hi.array()).any() ||
      result.z_lo < std::min(out.z_lo, in.z_lo) - slack ||
      result.z_hi > std::max(out.z_hi, in.z_hi) + slack)
    return StitchFailure::Distorted;
  IntersectionOptions all_pairs;
  all_pairs.between_components_only = false;
  if (!intersecting_face_pairs(result.V, result.F, all_pairs).empty())
    return StitchFailure::SelfIntersecting;
  return StitchFailure::None;
}

}  // namespace

std::optional<Element> cut_and_stitch(const Element& out, const Element& in,
                                      const OverlapRegion& region, double mean_edge_length,
                                      const MergeOptions& options, StitchFailure* failure,
                                      const EmbreeDevice* device) {
  auto fail = [&](StitchFailure why) -> std::optional<Element> {
    if (failure) *failure = why;
    return std::nullopt;
  };
  if (failure) *failure = StitchFailure::None;
  const double cover = options.cover_distance * mean_edge_length;
  const EmbreeDevice shared = device ? *device : EmbreeDevice();
  const ClosestPointQuery query_out(shared, out.V, out.F), query_in(shared, in.V, in.F);
  // Eq. (7) weights are in absolute units; scale distances by the edge length so the cut
  // behaves the same whatever the swatch's units.
  const double unit = mean_edge_length > 0 ? mean_edge_length : 1.0;
  const MatrixX3i TT_out = face_adjacency(edge_topology(out.F, static_cast<int>(out.V.rows())));
  const std::vector<CutLabel> labels_out = output_labels(out, TT_out, query_in, region, cover);
  const std::vector<bool> keep_out = graph_cut_keep_faces(
      out.V / unit, out.F, distances_off_keep(out, labels_out, query_in) / unit, labels_out);
  const std::vector<CutLabel> labels_in =
      swatch_labels(in, TT_out, keep_out, query_out, region, cover);
  const std::vector<bool> keep_in = graph_cut_keep_faces(
      in.V / unit, in.F, distances_off_keep(in, labels_in, query_out) / unit, labels_in);
  std::vector<int> from_out, from_in;
  const TriMesh a = kept_part(out, keep_out, from_out), b = kept_part(in, keep_in, from_in);
  if (a.F.rows() == 0 || b.F.rows() == 0) return fail(StitchFailure::EmptyCut);
  if (a.F.rows() == out.F.rows() || b.F.rows() == in.F.rows())
    return fail(StitchFailure::NothingCut);
  StitchOptions stitch_options;
  stitch_options.max_loop_distance = options.max_loop_distance * mean_edge_length;
  stitch_options.weld_tolerance = 0.25 * mean_edge_length;
  std::optional<StitchResult> stitched;
  try {
    stitched = stitch_cut_elements(a, b, stitch_options);
  } catch (const TopologyError&) {
    // The cut left a boundary that is not a set of simple loops (parts touching at a vertex).
    return fail(StitchFailure::BadSeam);
  }
  if (!stitched) return fail(StitchFailure::LoopsUnpaired);
  if (const StitchFailure why = seam_failure(stitched->mesh, out, in); why != StitchFailure::None)
    return fail(why);
  DeformationOptions deformation;
  deformation.mu = options.mu;
  Element result;
  result.V = deform_locally(stitched->mesh.V, stitched->mesh.F, stitched->constraints,
                            options.deformation_rings, options.solve_margin, deformation)
                 .V;
  result.F = stitched->mesh.F;
  result.kind = out.kind;  // partners are the same element placed twice (section 2.7)
  // The stitched vertices are the kept parts' (section 2.7 adds none), some of B's welded.
  std::vector<int> parts_vertex = from_out;
  for (const int v : from_in) parts_vertex.push_back(v);
  std::vector<int> from_out_kept, from_in_kept;
  for (const int v : stitched->origin)
    (v < a.num_vertices() ? from_out_kept : from_in_kept).push_back(parts_vertex[v]);
  carry_sources({{&out, &from_out_kept}, {&in, &from_in_kept}}, result);
  result.update();
  if (const StitchFailure why = merged_failure(result, out, in, mean_edge_length);
      why != StitchFailure::None)
    return fail(why);
  return result;
}

}  // namespace mq
