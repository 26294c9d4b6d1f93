#include "core/surface/surface_mask.h"

#include <algorithm>
#include <cmath>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"

namespace mq {

bool SurfaceMask::contains(const TriMesh& base, int f, const Vector3d& b) const {
  if (!face.empty()) return face[static_cast<size_t>(f)] != 0;
  double w = 0;
  for (int k = 0; k < 3; ++k) w += b(k) * vertex_weight(base.F(f, k));
  return w >= 0.5;
}

double masked_area_share(const SurfaceMask& mask, const TriMesh& base) {
  const Eigen::VectorXd area = face_areas(base.V, base.F);
  const Vector3d samples[4] = {Vector3d::Constant(1.0 / 3), Vector3d(2.0 / 3, 1.0 / 6, 1.0 / 6),
                               Vector3d(1.0 / 6, 2.0 / 3, 1.0 / 6),
                               Vector3d(1.0 / 6, 1.0 / 6, 2.0 / 3)};
  double in = 0;
  for (int f = 0; f < base.num_faces(); ++f)
    for (const Vector3d& b : samples) in += 0.25 * area(f) * (mask.contains(base, f, b) ? 1 : 0);
  const double total = area.sum();
  return total > 0 ? std::clamp(in / total, 0.0, 1.0) : 0.0;
}

std::vector<char> mask_quilt_faces(const SurfaceMask& mask, const TriMesh& base,
                                   const SurfaceQuilt& quilt) {
  return mask_faces(mask, base, quilt.base);
}

std::vector<char> mask_faces(const SurfaceMask& mask, const TriMesh& base, const TriMesh& refined) {
  MQ_CHECK(mask.face.empty() ? mask.vertex_weight.size() == base.num_vertices()
                             : static_cast<int>(mask.face.size()) == base.num_faces(),
           InvalidInput, "the mask does not fit the base (", base.num_vertices(), " vertices, ",
           base.num_faces(), " faces)");
  MatrixX3d centroids(refined.num_faces(), 3);
  for (int f = 0; f < refined.num_faces(); ++f)
    centroids.row(f) = (refined.V.row(refined.F(f, 0)) + refined.V.row(refined.F(f, 1)) +
                        refined.V.row(refined.F(f, 2))) /
                       3.0;
  const ClosestPointQuery query(base.V, base.F);
  const std::vector<ClosestPointHit> hits = query.closest(centroids);
  std::vector<char> out(static_cast<size_t>(refined.num_faces()), 0);
  for (int f = 0; f < refined.num_faces(); ++f) {
    const ClosestPointHit& h = hits[static_cast<size_t>(f)];
    out[static_cast<size_t>(f)] = h.face >= 0 && mask.contains(base, h.face, h.barycentric);
  }
  return out;
}

int drop_unmasked_elements(SurfaceQuilt& quilt, const std::vector<char>& faces) {
  MQ_CHECK(static_cast<int>(faces.size()) == quilt.base.num_faces(), InvalidInput, "the mask has ",
           faces.size(), " faces for the quilt's ", quilt.base.num_faces());
  const std::size_t before = quilt.elements.size();
  auto& elements = quilt.elements;
  elements.erase(std::remove_if(elements.begin(), elements.end(),
                                [&](const SurfaceElement& e) {
                                  std::size_t inside = 0;
                                  for (const int f : e.face)
                                    inside += faces[static_cast<size_t>(f)] != 0;
                                  return 2 * inside < e.face.size();
                                }),
                 elements.end());
  return static_cast<int>(before - quilt.elements.size());
}

}  // namespace mq
