#include "core/planar/element_correspondence.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace mq {

namespace {

// Marks the raster cells touched by each triangle's footprint box (a conservative raster).
std::vector<unsigned char> rasterize(const Element& e, const Vector2d& lo, double res, int nx,
                                     int ny) {
  std::vector<unsigned char> bits(static_cast<size_t>(nx) * ny, 0);
  for (int f = 0; f < e.F.rows(); ++f) {
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (int k = 0; k < 3; ++k) {
      x0 = std::min(x0, e.V(e.F(f, k), 0));
      x1 = std::max(x1, e.V(e.F(f, k), 0));
      y0 = std::min(y0, e.V(e.F(f, k), 1));
      y1 = std::max(y1, e.V(e.F(f, k), 1));
    }
    const int i0 = std::max(0, static_cast<int>((x0 - lo.x()) / res));
    const int i1 = std::min(nx - 1, static_cast<int>((x1 - lo.x()) / res));
    const int j0 = std::max(0, static_cast<int>((y0 - lo.y()) / res));
    const int j1 = std::min(ny - 1, static_cast<int>((y1 - lo.y()) / res));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) bits[static_cast<size_t>(j) * nx + i] = 1;
  }
  return bits;
}

}  // namespace

double footprint_overlap(const Element& a, const Element& b, double resolution) {
  const Vector2d lo = a.lo.cwiseMin(b.lo), hi = a.hi.cwiseMax(b.hi);
  const Vector2d ilo = a.lo.cwiseMax(b.lo), ihi = a.hi.cwiseMin(b.hi);
  if ((ilo.array() > ihi.array()).any()) return 0.0;
  // Raster over the union box, capped at 512 cells a side so huge elements stay cheap.
  const double res = std::max(resolution, (hi - lo).maxCoeff() / 512.0);
  if (!(res > 0)) return 1.0;  // both footprints degenerate to the same point
  const int nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / res)) + 1);
  const int ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / res)) + 1);
  const auto ra = rasterize(a, lo, res, nx, ny), rb = rasterize(b, lo, res, nx, ny);
  size_t na = 0, nb = 0, both = 0;
  for (size_t i = 0; i < ra.size(); ++i) {
    na += ra[i];
    nb += rb[i];
    both += ra[i] & rb[i];
  }
  return static_cast<double>(both) / static_cast<double>(std::max<size_t>(1, std::max(na, nb)));
}

bool projections_overlap(const Element& a, const Element& b, double resolution) {
  return footprint_overlap(a, b, resolution) > 0.0;
}

Correspondences find_correspondences(const std::vector<Element>& output,
                                     const std::vector<int>& candidates,
                                     const OverlapRegion& region, const PreparedSwatch& swatch,
                                     const SwatchFaceTree& swatch_faces, const Vector3d& t,
                                     const CorrespondenceOptions& options) {
  const double max_distance = options.prune_distance * swatch.mean_edge_length;
  // Per candidate element, its pairs; filled in parallel, concatenated in candidate order.
  std::vector<std::vector<VertexFacePair>> per_element(candidates.size());
  tbb::parallel_for(size_t(0), candidates.size(), [&](size_t i) {
    const int o = candidates[i];
    const Element& e = output[o];
    auto& pairs = per_element[i];
    // The previous vertex's face starts each search (a hint: it changes no minimum, and the
    // vertices of an element are visited in order, so ties resolve the same way every run).
    int hint = -1;
    for (int v = 0; v < e.V.rows(); ++v) {
      const Vector3d p = e.V.row(v).transpose();
      if (!region.contains(p)) continue;
      const Vector3d n = e.N.row(v).transpose();
      // A vertex whose faces all lost their area (squeezed by a deformation, or seen through a
      // degenerate patch map) has no normal: it cannot be matched by Eq. (1) and is skipped.
      if (!n.allFinite() || !(n.squaredNorm() > 0)) continue;
      // The Eq. (1)-closest swatch face among those within max_distance (the same search as
      // geometry matching, so pairs rank faces exactly as the matched cost did).
      const Vector3d q = p - t;
      int entry = -1;
      swatch_faces.min_face_cost(q, n, options.lambda, &entry, max_distance, hint);
      if (entry < 0) continue;
      hint = entry;
      if (n.dot(swatch_faces.entry_normal(entry)) < options.min_normal_dot) continue;
      const SwatchFaceTree::FacePoint closest = swatch_faces.entry_closest_point(entry, q);
      const int face = swatch_faces.entry_faces()[static_cast<size_t>(entry)];
      VertexFacePair pair;
      pair.out_element = o;
      pair.out_vertex = v;
      pair.in_element = swatch.face_element[face];
      pair.in_face = face - swatch.element_first_face[pair.in_element];
      pair.barycentric = closest.barycentric;
      pair.closest = closest.point + t;
      pair.distance = (q - closest.point).norm();
      pairs.push_back(pair);
    }
  });
  Correspondences result;
  for (auto& pairs : per_element)
    for (const auto& p : pairs) result.relations.emplace_back(p.out_element, p.in_element);
  std::sort(result.relations.begin(), result.relations.end());
  result.relations.erase(std::unique(result.relations.begin(), result.relations.end()),
                         result.relations.end());
  // Drop relations whose projections do not overlap (false correspondences, section 2.5).
  std::vector<char> keep(result.relations.size(), 1);
  tbb::parallel_for(size_t(0), result.relations.size(), [&](size_t r) {
    const auto [o, in] = result.relations[r];
    Element moved = swatch.elements[in];
    moved.translate(t);
    keep[r] = projections_overlap(output[o], moved, swatch.mean_edge_length);
  });
  std::vector<std::pair<int, int>> relations;
  for (size_t r = 0; r < keep.size(); ++r)
    if (keep[r]) relations.push_back(result.relations[r]);
  result.relations = std::move(relations);
  for (auto& pairs : per_element)
    for (const auto& p : pairs)
      if (std::binary_search(result.relations.begin(), result.relations.end(),
                             std::make_pair(p.out_element, p.in_element)))
        result.pairs.push_back(p);
  return result;
}

}  // namespace mq
