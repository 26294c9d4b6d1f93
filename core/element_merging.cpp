#include "core/element_merging.h"

#include "core/boundary_loops.h"
#include "core/closest_point_query.h"
#include "core/element_cut.h"
#include "core/element_stitch.h"
#include "core/errors.h"
#include "core/laplacian_deformation.h"
#include "core/mesh_topology.h"

namespace mq {

namespace {

TriMesh as_mesh(const Element& e) {
  TriMesh m;
  m.V = e.V;
  m.F = e.F;
  return m;
}

int count_boundary_edges(const MatrixX3i& F, int nv) {
  const EdgeTopology topo = edge_topology(F, nv);
  int n = 0;
  for (int e = 0; e < topo.num_edges(); ++e) n += topo.is_boundary(e);
  return n;
}

// Hard labels of section 2.7 for cutting element `a` against its partner `b`.
std::vector<CutLabel> hard_labels(const Element& a, const Element& b,
                                  const ClosestPointQuery& query_b, const OverlapRegion& region,
                                  double cover) {
  const int nf = static_cast<int>(a.F.rows());
  std::vector<CutLabel> hard(nf, CutLabel::Free);
  // Faces of b that have a partner on a (their centroid lies close to a).
  const ClosestPointQuery query_a(a.V, a.F);
  const int nfb = static_cast<int>(b.F.rows());
  std::vector<char> b_covered(nfb, 0), b_outside(nfb, 0);
  for (int g = 0; g < nfb; ++g) {
    const Vector3d c =
        (b.V.row(b.F(g, 0)) + b.V.row(b.F(g, 1)) + b.V.row(b.F(g, 2))).transpose() / 3.0;
    b_covered[g] = query_a.closest(c, cover).face >= 0;
    b_outside[g] = !region.contains(c);
  }
  const MatrixX3i TT = face_adjacency(edge_topology(b.F, static_cast<int>(b.V.rows())));
  const Adjacency vf = vertex_faces(a.F, static_cast<int>(a.V.rows()));
  std::vector<char> sink_vertex(a.V.rows(), 0);
  for (int v = 0; v < a.V.rows(); ++v) {
    const ClosestPointHit hit = query_b.closest(Vector3d(a.V.row(v).transpose()), cover);
    if (hit.face < 0) continue;
    bool rim = b_outside[hit.face] != 0;
    for (int k = 0; k < 3 && !rim; ++k) {
      const int g = TT(hit.face, k);
      rim = g < 0 || !b_covered[g];
    }
    sink_vertex[v] = rim;
  }
  for (int v = 0; v < a.V.rows(); ++v)
    if (sink_vertex[v])
      for (const int* f = vf.begin(v); f != vf.end(v); ++f) hard[*f] = CutLabel::Remove;
  // Outside the overlap: always kept (SOURCE wins over SINK so the cut stays feasible).
  for (int f = 0; f < nf; ++f) {
    bool outside = true;
    for (int k = 0; k < 3; ++k) outside = outside && !region.contains(a.V.row(a.F(f, k)));
    if (outside) hard[f] = CutLabel::Keep;
  }
  return hard;
}

TriMesh kept_part(const Element& e, const std::vector<bool>& keep) {
  std::vector<int> faces;
  for (size_t f = 0; f < keep.size(); ++f)
    if (keep[f]) faces.push_back(static_cast<int>(f));
  return extract_faces(as_mesh(e), faces);
}

}  // namespace

bool elements_coincide(const Element& a, const Element& b, double tolerance) {
  const ClosestPointQuery qa(a.V, a.F), qb(b.V, b.F);
  for (int v = 0; v < a.V.rows(); ++v)
    if (qb.closest(Vector3d(a.V.row(v).transpose()), tolerance).face < 0) return false;
  for (int v = 0; v < b.V.rows(); ++v)
    if (qa.closest(Vector3d(b.V.row(v).transpose()), tolerance).face < 0) return false;
  return true;
}

std::optional<Element> cut_and_stitch(const Element& out, const Element& in,
                                      const OverlapRegion& region, double mean_edge_length,
                                      const MergeOptions& options, StitchFailure* failure) {
  auto fail = [&](StitchFailure why) -> std::optional<Element> {
    if (failure) *failure = why;
    return std::nullopt;
  };
  if (failure) *failure = StitchFailure::None;
  const double cover = options.cover_distance * mean_edge_length;
  const ClosestPointQuery query_out(out.V, out.F), query_in(in.V, in.F);
  Eigen::VectorXd dist_out(out.V.rows()), dist_in(in.V.rows());
  for (int v = 0; v < out.V.rows(); ++v)
    dist_out(v) = query_in.closest(Vector3d(out.V.row(v).transpose())).distance;
  for (int v = 0; v < in.V.rows(); ++v)
    dist_in(v) = query_out.closest(Vector3d(in.V.row(v).transpose())).distance;
  // Eq. (7) weights are in absolute units; scale distances by the edge length so the cut
  // behaves the same whatever the swatch's units.
  const double unit = mean_edge_length > 0 ? mean_edge_length : 1.0;
  const MatrixX3d out_V = out.V / unit, in_V = in.V / unit;
  const std::vector<bool> keep_out =
      graph_cut_keep_faces(out_V, out.F, dist_out / unit,
                           hard_labels(out, in, query_in, region, cover));
  const std::vector<bool> keep_in =
      graph_cut_keep_faces(in_V, in.F, dist_in / unit, hard_labels(in, out, query_out, region, cover));
  const TriMesh a = kept_part(out, keep_out), b = kept_part(in, keep_in);
  if (a.F.rows() == 0 || b.F.rows() == 0) return fail(StitchFailure::EmptyCut);
  if (a.F.rows() == out.F.rows() || b.F.rows() == in.F.rows())
    return fail(StitchFailure::NothingCut);
  StitchOptions stitch_options;
  stitch_options.max_loop_distance = options.max_loop_distance * mean_edge_length;
  std::optional<StitchResult> stitched;
  try {
    stitched = stitch_cut_elements(a, b, stitch_options);
  } catch (const TopologyError&) {
    // The min cut may leave a bow-tie or an edge shared by several kept faces; keeping one
    // element whole is the documented fallback rather than aborting the whole synthesis.
    return fail(StitchFailure::NonManifoldCut);
  }
  if (!stitched) return fail(StitchFailure::LoopsUnpaired);
  std::vector<int> fc;
  if (connected_components(stitched->mesh.F, stitched->mesh.num_vertices(), fc) != 1)
    return fail(StitchFailure::NotOneComponent);
  const int boundary = count_boundary_edges(stitched->mesh.F, stitched->mesh.num_vertices());
  const int allowed = count_boundary_edges(out.F, static_cast<int>(out.V.rows())) +
                      count_boundary_edges(in.F, static_cast<int>(in.V.rows()));
  if (boundary > allowed) return fail(StitchFailure::OpenSeam);
  DeformationOptions deformation;
  deformation.mu = options.mu;
  Element result;
  result.V = deform_element(stitched->mesh.V, stitched->mesh.F, stitched->constraints, deformation);
  result.F = stitched->mesh.F;
  result.update();
  return result;
}

}  // namespace mq
