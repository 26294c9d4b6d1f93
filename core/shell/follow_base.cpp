#include "core/shell/follow_base.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

void FollowBaseOptions::validate() const {
  MQ_CHECK(std::isfinite(rigid_radius) && rigid_radius >= 0, InvalidInput,
           "the rigid radius must be >= 0 and finite, got ", rigid_radius);
}

namespace {

// The rotation R minimising sum |R (p_i - cp) - (q_i - cq)|^2 (Kabsch; a reflection is
// replaced by the nearest rotation).
Eigen::Matrix3d best_rotation(const Eigen::Matrix3d& covariance) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixV() * D * svd.matrixU().transpose();
}

}  // namespace

TriMesh follow_base(const SavedQuilt& saved, const MatrixX3d& V, const FollowBaseOptions& options,
                    FollowBaseStats* stats) {
  options.validate();
  MQ_CHECK(V.rows() == saved.base.V.rows() && V.allFinite(), InvalidInput,
           "follow_base: ", V.rows(), " base positions for a welded base of ", saved.base.V.rows(),
           " vertices, or a position not finite");
  const double H = saved.header.shell_height;
  const MatrixX3i& F = saved.base.F;
  const MatrixX3d N_rest = vertex_normals(saved.base.V, F), N = vertex_normals(V, F);
  const MatrixX3d& P = saved.output.V;
  std::vector<int> face_component;
  const int elements =
      connected_components(saved.output.F, saved.output.num_vertices(), face_component);
  const std::vector<std::vector<int>> faces = component_faces(face_component, elements);

  MQ_CHECK(options.remove.empty() || static_cast<int>(options.remove.size()) == elements,
           InvalidInput, "follow_base: ", options.remove.size(), " removal flags for ", elements,
           " elements");
  TriMesh out = saved.output;
  MatrixX3d Q = saved.output.V;                              // following the surface
  std::vector<char> kind(static_cast<size_t>(elements), 0);  // 0 unmoved, 1 rigid, 2 following
  std::vector<double> offset(static_cast<size_t>(elements), 0.0);
  tbb::parallel_for(0, elements, [&](int e) {
    // The element's vertices, each once, in order.
    std::vector<int> vs;
    for (const int f : faces[static_cast<size_t>(e)])
      for (int k = 0; k < 3; ++k) vs.push_back(saved.output.F(f, k));
    std::sort(vs.begin(), vs.end());
    vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    // Where each vertex goes following the surface: its rest position plus what its prism
    // coordinates move by (zero, bit for bit, where the base did not move).
    std::vector<Vector3d> q(vs.size());
    bool moved = false;
    for (size_t i = 0; i < vs.size(); ++i) {
      const int v = vs[i];
      const int f = saved.coords.face[static_cast<size_t>(v)];
      const Vector3d bt = saved.coords.bt.row(v).transpose();
      const Vector3d d =
          prism_point(V, F, N, H, f, bt) - prism_point(saved.base.V, F, N_rest, H, f, bt);
      moved = moved || (d.array() != 0.0).any();
      q[i] = P.row(v).transpose() + d;
      Q.row(v) = q[i].transpose();
    }
    if (!moved) return;
    Vector3d cp = Vector3d::Zero(), cq = Vector3d::Zero();
    for (size_t i = 0; i < vs.size(); ++i) {
      cp += P.row(vs[i]).transpose();
      cq += q[i];
    }
    cp /= static_cast<double>(vs.size());
    cq /= static_cast<double>(vs.size());
    double radius = 0;
    for (const int v : vs) radius = std::max(radius, (P.row(v).transpose() - cp).norm());
    if (radius > options.rigid_radius * H) {
      for (size_t i = 0; i < vs.size(); ++i) out.V.row(vs[i]) = q[i].transpose();
      kind[static_cast<size_t>(e)] = 2;
      return;
    }
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < vs.size(); ++i)
      covariance += (P.row(vs[i]).transpose() - cp) * (q[i] - cq).transpose();
    const Eigen::Matrix3d R = best_rotation(covariance);
    double largest = 0;
    for (size_t i = 0; i < vs.size(); ++i) {
      const Vector3d x = R * (P.row(vs[i]).transpose() - cp) + cq;
      largest = std::max(largest, (x - q[i]).norm());
      out.V.row(vs[i]) = x.transpose();
    }
    kind[static_cast<size_t>(e)] = 1;
    offset[static_cast<size_t>(e)] = largest / H;
  });
  // Rigid elements pressed into a neighbour follow the surface instead; what still intersects
  // goes (the later element of each pair, as the post-processing's removal).
  std::vector<char> removed = options.remove;
  removed.resize(static_cast<size_t>(elements), 0);
  int unbent = 0;
  if (options.resolve_intersections) {
    auto intersecting = [&](const std::vector<char>& element_active) {
      std::vector<char> active(static_cast<size_t>(out.num_faces()), 0);
      bool any = false;
      for (int f = 0; f < out.num_faces(); ++f)
        any |= (active[static_cast<size_t>(f)] =
                    element_active[static_cast<size_t>(face_component[static_cast<size_t>(f)])]);
      std::vector<std::pair<int, int>> pairs;
      if (!any) return pairs;
      for (const auto& [f, g] :
           intersecting_face_pairs_touching(out.V, out.F, active, face_component, false)) {
        const int a = face_component[static_cast<size_t>(f)],
                  b = face_component[static_cast<size_t>(g)];
        if (a != b && !removed[static_cast<size_t>(a)] && !removed[static_cast<size_t>(b)])
          pairs.emplace_back(std::min(a, b), std::max(a, b));
      }
      std::sort(pairs.begin(), pairs.end());
      pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
      return pairs;
    };
    // Only rigid elements that moved away from the surface's motion can newly touch another.
    std::vector<char> active(static_cast<size_t>(elements), 0);
    for (int e = 0; e < elements; ++e)
      active[static_cast<size_t>(e)] = kind[static_cast<size_t>(e)] == 1 &&
                                       offset[static_cast<size_t>(e)] > 0 &&
                                       !removed[static_cast<size_t>(e)];
    std::vector<char> changed(static_cast<size_t>(elements), 0);
    for (const auto& [a, b] : intersecting(active))
      for (const int e : {a, b})
        if (kind[static_cast<size_t>(e)] == 1 && !changed[static_cast<size_t>(e)]) {
          changed[static_cast<size_t>(e)] = 1;
          ++unbent;
          for (const int f : faces[static_cast<size_t>(e)])
            for (int k = 0; k < 3; ++k) out.V.row(out.F(f, k)) = Q.row(out.F(f, k));
        }
    for (const auto& [a, b] : intersecting(changed)) {
      if (removed[static_cast<size_t>(a)] || removed[static_cast<size_t>(b)]) continue;
      removed[static_cast<size_t>(b)] = 1;
    }
    // Following the surface can fold an element through itself where the surface creases
    // (the synthesis removes such elements too).
    std::vector<char> changed_faces(static_cast<size_t>(out.num_faces()), 0);
    for (int f = 0; f < out.num_faces(); ++f)
      changed_faces[static_cast<size_t>(f)] =
          changed[static_cast<size_t>(face_component[static_cast<size_t>(f)])];
    if (unbent > 0)
      for (const auto& [f, g] :
           intersecting_face_pairs_touching(out.V, out.F, changed_faces, face_component, true))
        removed[static_cast<size_t>(face_component[static_cast<size_t>(f)])] = 1;
  }
  if (std::find(removed.begin(), removed.end(), 1) != removed.end()) {
    std::vector<int> keep;
    for (int f = 0; f < out.num_faces(); ++f)
      if (!removed[static_cast<size_t>(face_component[static_cast<size_t>(f)])]) keep.push_back(f);
    out = extract_faces(out, keep);  // kinds and face kinds carried
  }
  if (stats) {
    *stats = FollowBaseStats{};
    stats->unbent = unbent;
    stats->removed = removed;
    stats->num_removed = static_cast<int>(std::count(removed.begin(), removed.end(), 1));
    stats->elements = elements;
    for (int e = 0; e < elements; ++e) {
      const char k = kind[static_cast<size_t>(e)];
      (k == 0 ? stats->unmoved : k == 1 ? stats->rigid : stats->following) += 1;
      stats->largest_rigid_offset =
          std::max(stats->largest_rigid_offset, offset[static_cast<size_t>(e)]);
    }
  }
  return out;
}

}  // namespace mq
