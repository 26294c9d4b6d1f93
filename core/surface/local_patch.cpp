#include "core/surface/local_patch.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/surface/lscm.h"

namespace mq {

LocalPatchBuilder::LocalPatchBuilder(const TriMesh& base)
    : base_(&base), topo_(edge_topology(base.F, base.num_vertices())), TT_(face_adjacency(topo_)) {
  init();
}

LocalPatchBuilder::LocalPatchBuilder(const TriMesh& base, const EdgeTopology& topo,
                                     const MatrixX3i& TT)
    : base_(&base), topo_(topo), TT_(TT) {
  init();
}

void LocalPatchBuilder::init() {
  const TriMesh& base = *base_;
  const int nf = base.num_faces(), nv = base.num_vertices();
  MQ_CHECK(TT_.rows() == nf && topo_.FE.rows() == nf, InvalidInput,
           "LocalPatchBuilder: topology has ", topo_.FE.rows(), " / ", TT_.rows(),
           " face rows for a base mesh with ", nf, " faces");
  MQ_CHECK(base.V.allFinite(), InvalidInput, "LocalPatchBuilder: non-finite base vertex");
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(base.F(f, k) >= 0 && base.F(f, k) < nv, InvalidInput, "LocalPatchBuilder: face ", f,
               " has vertex index ", base.F(f, k), " out of range");
  area_ = face_areas(base.V, base.F);
  centroid_.resize(nf, 3);
  for (int f = 0; f < nf; ++f)
    centroid_.row(f) =
        (base.V.row(base.F(f, 0)) + base.V.row(base.F(f, 1)) + base.V.row(base.F(f, 2))) / 3.0;
  distance_.assign(nf, 0.0);
  seed_image_.resize(nf, 3);
  usable_.resize(nf);
  for (int f = 0; f < nf; ++f)
    usable_[f] = area_(f) > 0 && base.F(f, 0) != base.F(f, 1) && base.F(f, 1) != base.F(f, 2) &&
                 base.F(f, 2) != base.F(f, 0);
  face_in_patch_.assign(nf, 0);
  face_seen_.assign(nf, 0);
  vertex_in_patch_.assign(nv, 0);
  vertex_local_tick_.assign(nv, 0);
  vertex_local_.assign(nv, -1);
}

uint32_t LocalPatchBuilder::next_tick() {
  if (++tick_ == 0) {  // wrapped: clear the stamps once every 2^32 ticks
    std::fill(face_in_patch_.begin(), face_in_patch_.end(), 0);
    std::fill(face_seen_.begin(), face_seen_.end(), 0);
    std::fill(vertex_in_patch_.begin(), vertex_in_patch_.end(), 0);
    std::fill(vertex_local_tick_.begin(), vertex_local_tick_.end(), 0);
    tick_ = 1;
  }
  return tick_;
}

// Rotates point p, lying in face f's plane, about f's edge k into the plane of face g (the face
// across that edge), as if the two faces were unfolded flat: p keeps its coordinate along the
// edge and its distance from it, and moves to the side opposite g's third vertex.
Vector3d LocalPatchBuilder::unfold_across(int f, int k, int g, const Vector3d& p) const {
  const MatrixX3i& F = base_->F;
  const int fa = F(f, k), fb = F(f, (k + 1) % 3);
  const Vector3d a = base_->V.row(fa).transpose();
  const Vector3d e = (base_->V.row(fb).transpose() - a).normalized();
  int gc = F(g, 0);
  for (int j = 0; j < 3; ++j)
    if (F(g, j) != fa && F(g, j) != fb) gc = F(g, j);
  const Vector3d fc = base_->V.row(F(f, (k + 2) % 3)).transpose();
  const Vector3d q = base_->V.row(gc).transpose() - a;
  Vector3d pf = (fc - a) - (fc - a).dot(e) * e;  // in f's plane, towards f's third vertex
  Vector3d pg = q - q.dot(e) * e;                // in g's plane, towards g's third vertex
  const double nf = pf.norm(), ng = pg.norm();
  if (!(nf > 0) || !(ng > 0)) return p;  // degenerate: leave the image where it is
  pf /= nf;
  pg /= ng;
  const Vector3d r = p - a;
  return a + r.dot(e) * e - r.dot(pf) * pg;
}

// Disk-preserving test for a face outside the patch (which is a disk with a simple boundary).
bool LocalPatchBuilder::can_add(int f) const {
  if (!usable_[f]) return false;
  int shared = 0, free_edge = -1, in_patch = 0;
  for (int k = 0; k < 3; ++k) {
    const int g = TT_(f, k);
    if (g >= 0 && face_in_patch_[g] == patch_tick_)
      ++shared;
    else
      free_edge = k;
    if (vertex_in_patch_[base_->F(f, k)] == patch_tick_) ++in_patch;
  }
  // One shared edge and a new vertex: the disk grows by a triangle on its boundary.
  if (shared == 1) return in_patch == 2;
  // Two shared edges: the face closes a notch at their common vertex; the third edge must not
  // already be in the patch (possible only through a non-manifold base edge).
  if (shared == 2) {
    const int e = topo_.FE(f, free_edge);
    for (const int* g = topo_.edge_faces.begin(e); g != topo_.edge_faces.end(e); ++g)
      if (face_in_patch_[*g] == patch_tick_) return false;
    return true;
  }
  return false;  // three shared edges would close the surface
}

void LocalPatchBuilder::flatten(LocalPatch& patch, size_t num_faces) {
  patch.faces.resize(num_faces);
  const uint32_t tick = next_tick();
  const MatrixX3i& BF = base_->F;
  patch.vertex_map.clear();
  patch.mesh.F.resize(static_cast<Eigen::Index>(num_faces), 3);
  patch.area = 0;
  for (size_t i = 0; i < num_faces; ++i) {
    const int f = patch.faces[i];
    patch.area += area_(f);
    for (int k = 0; k < 3; ++k) {
      const int v = BF(f, k);
      if (vertex_local_tick_[v] != tick) {
        vertex_local_tick_[v] = tick;
        vertex_local_[v] = static_cast<int>(patch.vertex_map.size());
        patch.vertex_map.push_back(v);
      }
      patch.mesh.F(static_cast<Eigen::Index>(i), k) = vertex_local_[v];
    }
  }
  patch.mesh.V.resize(static_cast<Eigen::Index>(patch.vertex_map.size()), 3);
  for (size_t i = 0; i < patch.vertex_map.size(); ++i)
    patch.mesh.V.row(static_cast<Eigen::Index>(i)) = base_->V.row(patch.vertex_map[i]);
  patch.mesh.N.resize(0, 3);
  patch.uv = lscm(patch.mesh.V, patch.mesh.F);
  const Eigen::VectorXd d = face_area_distortion(patch.mesh.V, patch.mesh.F, patch.uv);
  patch.max_distortion = d.maxCoeff();
  // The patch is judged by its 95th percentile: a few slivers at the rim of a good patch must
  // not shrink it (their distortion explodes first as the rim curls away).
  std::vector<double> sorted(d.data(), d.data() + d.size());
  const size_t k = std::min(sorted.size() - 1, sorted.size() * 95 / 100);
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  patch.distortion = sorted[k];
}

LocalPatch LocalPatchBuilder::grow(int seed_face, const LocalPatchOptions& options) {
  const int nf = base_->num_faces();
  MQ_CHECK(seed_face >= 0 && seed_face < nf, InvalidInput, "local patch: seed face ", seed_face,
           " out of range [0, ", nf, ")");
  MQ_CHECK(usable_[seed_face], InvalidInput, "local patch: seed face ", seed_face,
           " is degenerate");
  MQ_CHECK(std::isfinite(options.max_area) && options.max_area >= 0, InvalidInput,
           "local patch: max_area must be finite and >= 0, got ", options.max_area);
  MQ_CHECK(std::isfinite(options.max_radius) && options.max_radius >= 0, InvalidInput,
           "local patch: max_radius must be finite and >= 0, got ", options.max_radius);
  MQ_CHECK(options.max_distortion >= 1, InvalidInput,
           "local patch: max_distortion must be >= 1, got ", options.max_distortion);

  LocalPatch patch;
  patch_tick_ = next_tick();
  double area = 0;
  const bool limit_area = options.max_area > 0;
  const bool limit_radius = options.max_radius > 0;
  // Faces join nearest first. A face's distance is that of its centroid from the seed centroid
  // unfolded into its plane across the chain of faces that reached it (exact on developable
  // surfaces such as the folded sides of a box, and never below the straight 3D distance), so
  // the patch approximates a geodesic disk whatever the triangle shapes; breadth-first layers
  // stretched patches along the long side of thin triangles (a pillar of the brick wall got
  // 0.6 x 3.5 strips on which no ivy element fits).
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  const MatrixX3i& BF = base_->F;
  const Vector3d seed_point = centroid_.row(seed_face).transpose();
  auto add = [&](int f) {
    face_in_patch_[f] = patch_tick_;
    for (int k = 0; k < 3; ++k) vertex_in_patch_[BF(f, k)] = patch_tick_;
    patch.faces.push_back(f);
    area += area_(f);
    // A face refused before is queued again: the new neighbour may make it a notch to close.
    for (int k = 0; k < 3; ++k) {
      const int g = TT_(f, k);
      if (g < 0 || face_in_patch_[g] == patch_tick_) continue;
      const Vector3d image = unfold_across(f, k, g, seed_image_.row(f).transpose());
      const Vector3d c = centroid_.row(g).transpose();
      const double d = std::max((c - image).norm(), (c - seed_point).norm());
      if (face_seen_[g] != patch_tick_ || d < distance_[g]) {
        face_seen_[g] = patch_tick_;
        distance_[g] = d;
        seed_image_.row(g) = image.transpose();
      }
      queue.emplace(distance_[g], g);
    }
  };
  face_seen_[seed_face] = patch_tick_;
  distance_[seed_face] = 0;
  seed_image_.row(seed_face) = seed_point.transpose();
  add(seed_face);
  while (!queue.empty() && !(limit_area && area >= options.max_area)) {
    const auto [d, f] = queue.top();
    queue.pop();
    if (face_in_patch_[f] == patch_tick_ || d > distance_[f]) continue;  // taken or stale
    if (limit_radius && d > options.max_radius) break;
    if (can_add(f)) add(f);
  }

  flatten(patch, patch.faces.size());
  while ((patch.distortion > options.max_distortion || count_flipped(patch.mesh.F, patch.uv) > 0) &&
         patch.faces.size() > 1) {
    // Halve the area: the longest growth-order prefix within half of it (at least the seed).
    const double target = 0.5 * patch.area;
    size_t keep = 1;
    double prefix = area_(patch.faces[0]);
    while (keep < patch.faces.size() && prefix + area_(patch.faces[keep]) <= target)
      prefix += area_(patch.faces[keep++]);
    ++patch.shrink_steps;
    flatten(patch, keep);
  }
  return patch;
}

LocalPatch grow_local_patch(const TriMesh& base, const EdgeTopology& topo, const MatrixX3i& TT,
                            int seed_face, const LocalPatchOptions& options) {
  return LocalPatchBuilder(base, topo, TT).grow(seed_face, options);
}

}  // namespace mq
