#include "core/shell/follow_base.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/similarity_fit.h"
#include "core/shell/element_editing.h"

namespace mq {

void FollowBaseOptions::validate() const {
  MQ_CHECK(std::isfinite(rigid_radius) && rigid_radius >= 0, InvalidInput,
           "the rigid radius must be >= 0 and finite, got ", rigid_radius);
}

namespace {

// Intersection tests among the elements of `out` near a few active ones: the faces of the
// active elements and of those whose boxes overlap theirs, not the whole output.
class ElementPairs {
 public:
  ElementPairs(TriMesh& out, const std::vector<int>& face_component,
               const std::vector<std::vector<int>>& faces, int elements)
      : out_(out),
        face_component_(face_component),
        faces_(faces),
        scaled_(static_cast<size_t>(elements), 0) {}

  // Pairs (a < b) of elements, neither removed, at least one active, that intersect.
  std::vector<std::pair<int, int>> intersecting(const std::vector<char>& active,
                                                const std::vector<char>& removed) const {
    std::vector<std::pair<int, int>> pairs;
    for (const auto& [f, g] : face_pairs(active, removed, false)) {
      const int a = face_component_[static_cast<size_t>(f)],
                b = face_component_[static_cast<size_t>(g)];
      pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return pairs;
  }

  // Active elements folded through themselves.
  std::vector<int> self_intersecting(const std::vector<char>& active) const {
    std::vector<int> result;
    const std::vector<char> none(active.size(), 0);
    for (const auto& [f, g] : face_pairs(active, none, true))
      result.push_back(face_component_[static_cast<size_t>(f)]);
    std::sort(result.begin(), result.end());
    result.erase(std::unique(result.begin(), result.end()), result.end());
    return result;
  }

  // Element e as in `from`, scaled by s about its centroid.
  void scale(int e, const MatrixX3d& from, double s) {
    std::vector<int> vs = vertices(e);
    Vector3d c = Vector3d::Zero();
    for (const int v : vs) c += from.row(v).transpose();
    c /= static_cast<double>(vs.size());
    for (const int v : vs) out_.V.row(v) = (c + s * (from.row(v).transpose() - c)).transpose();
    scaled_[static_cast<size_t>(e)] = 1;
  }
  bool was_scaled(int e) const { return scaled_[static_cast<size_t>(e)] != 0; }

 private:
  std::vector<int> vertices(int e) const {
    std::vector<int> vs;
    for (const int f : faces_[static_cast<size_t>(e)])
      for (int k = 0; k < 3; ++k) vs.push_back(out_.F(f, k));
    std::sort(vs.begin(), vs.end());
    vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    return vs;
  }

  // Face pairs of the sub-mesh of active elements and their neighbours (boxes overlapping),
  // in the output's face numbers.
  std::vector<std::pair<int, int>> face_pairs(const std::vector<char>& active,
                                              const std::vector<char>& removed,
                                              bool same_element) const {
    const int elements = static_cast<int>(faces_.size());
    std::vector<Eigen::AlignedBox3d> box(static_cast<size_t>(elements));
    std::vector<int> act;
    for (int e = 0; e < elements; ++e) {
      if (removed[static_cast<size_t>(e)]) continue;
      for (const int f : faces_[static_cast<size_t>(e)])
        for (int k = 0; k < 3; ++k)
          box[static_cast<size_t>(e)].extend(Vector3d(out_.V.row(out_.F(f, k))));
      if (active[static_cast<size_t>(e)]) act.push_back(e);
    }
    if (act.empty()) return {};
    // Candidates: a sweep along x over the boxes, sorted by their lower x.
    std::vector<int> order;
    for (int e = 0; e < elements; ++e)
      if (!removed[static_cast<size_t>(e)]) order.push_back(e);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return box[static_cast<size_t>(a)].min().x() < box[static_cast<size_t>(b)].min().x() ||
             (box[static_cast<size_t>(a)].min().x() == box[static_cast<size_t>(b)].min().x() &&
              a < b);
    });
    std::vector<char> take(static_cast<size_t>(elements), 0);
    for (const int e : act) take[static_cast<size_t>(e)] = 1;
    if (!same_element) {
      std::vector<int> open;  // boxes whose x range still reaches the sweep
      for (const int e : order) {
        const auto& be = box[static_cast<size_t>(e)];
        open.erase(std::remove_if(
                       open.begin(), open.end(),
                       [&](int o) { return box[static_cast<size_t>(o)].max().x() < be.min().x(); }),
                   open.end());
        for (const int o : open)
          if ((active[static_cast<size_t>(o)] || active[static_cast<size_t>(e)]) &&
              be.intersects(box[static_cast<size_t>(o)]))
            take[static_cast<size_t>(o)] = take[static_cast<size_t>(e)] = 1;
        open.push_back(e);
      }
    }
    std::vector<int> sub_faces, label;
    std::vector<char> sub_active;
    for (int e = 0; e < elements; ++e)
      if (take[static_cast<size_t>(e)])
        for (const int f : faces_[static_cast<size_t>(e)]) {
          sub_faces.push_back(f);
          label.push_back(e);
          sub_active.push_back(active[static_cast<size_t>(e)]);
        }
    MatrixX3i F(static_cast<Eigen::Index>(sub_faces.size()), 3);
    for (size_t i = 0; i < sub_faces.size(); ++i)
      F.row(static_cast<Eigen::Index>(i)) = out_.F.row(sub_faces[i]);
    std::vector<std::pair<int, int>> result;
    for (const auto& [f, g] :
         intersecting_face_pairs_touching(out_.V, F, sub_active, label, same_element))
      result.emplace_back(sub_faces[static_cast<size_t>(f)], sub_faces[static_cast<size_t>(g)]);
    return result;
  }

  TriMesh& out_;
  const std::vector<int>& face_component_;
  const std::vector<std::vector<int>>& faces_;
  std::vector<char> scaled_;
};

}  // namespace

SavedQuilt make_saved_quilt(const SurfaceQuilt& quilt, const TriMesh& output,
                            SavedQuiltHeader header, int* inexact) {
  // Under a proxy the output is located over the base as given (welded): the proxy lies within
  // a twentieth of the shell height of it, so the prisms over it hold the output too.
  const bool proxy = quilt.input_vertex.empty();
  const TriMesh& base = proxy ? quilt.welded_base : quilt.input_base;
  const std::vector<int>& input_vertex = proxy ? quilt.welded_input_vertex : quilt.input_vertex;
  MQ_CHECK(static_cast<Eigen::Index>(input_vertex.size()) == base.V.rows() && !input_vertex.empty(),
           InvalidInput, "the quilt cannot be saved: its base as given was not kept");
  SavedQuilt saved;
  header.shell_height = quilt.shell_height;
  saved.header = std::move(header);
  saved.input_vertex = input_vertex;
  saved.base.V = base.V;
  saved.base.F = base.F;
  saved.output.V = output.V;
  saved.output.F = output.F;
  saved.output.kinds = output.kinds;
  saved.output.face_kind = output.face_kind;
  saved.coords =
      locate_in_prisms(saved.base.V, saved.base.F, vertex_normals(saved.base.V, saved.base.F),
                       quilt.shell_height, output.V, inexact);
  return saved;
}

namespace {

// The saved output on the moved base, element by element, as the steps below leave it.
struct Following {
  TriMesh out;                          // the result so far
  MatrixX3d Q;                          // every vertex following the surface
  std::vector<int> face_component;      // #F(output): the element of each face
  std::vector<std::vector<int>> faces;  // per element: its faces
  int elements = 0;
  std::vector<char> kind;      // per element: 0 unmoved, 1 rigid, 2 following
  std::vector<double> offset;  // per rigid element: largest offset from Q, in H
  std::vector<char> removed;   // per element
  int unbent = 0, shrunk = 0, still_pressed = 0;
};

// Element e on the moved base (positions V, vertex normals N; at rest N_rest): each vertex where
// its prism coordinates take it (zero move, bit for bit, where the base did not move); a compact
// element (within options.rigid_radius shell heights of its centre) then moved rigidly by the
// rotation that best fits those positions (bent by the surface, not stretched with it).
void place_element(const SavedQuilt& saved, const MatrixX3d& V, const MatrixX3d& N,
                   const MatrixX3d& N_rest, const FollowBaseOptions& options, int e, Following& w) {
  const double H = saved.header.shell_height;
  const MatrixX3i& F = saved.base.F;
  const MatrixX3d& P = saved.output.V;
  // The element's vertices, each once, in order.
  std::vector<int> vs;
  for (const int f : w.faces[static_cast<size_t>(e)])
    for (int k = 0; k < 3; ++k) vs.push_back(saved.output.F(f, k));
  std::sort(vs.begin(), vs.end());
  vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
  std::vector<Vector3d> q(vs.size());
  bool moved = false;
  for (size_t i = 0; i < vs.size(); ++i) {
    const int v = vs[i];
    const int f = saved.coords.face(v);
    const Vector3d b = saved.coords.bary.row(v).transpose();
    const double h = saved.coords.height(v);
    const Vector3d d =
        prism_point(V, F, N, f, b, h) - prism_point(saved.base.V, F, N_rest, f, b, h);
    moved = moved || (d.array() != 0.0).any();
    q[i] = P.row(v).transpose() + d;
    w.Q.row(v) = q[i].transpose();
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
    for (size_t i = 0; i < vs.size(); ++i) w.out.V.row(vs[i]) = q[i].transpose();
    w.kind[static_cast<size_t>(e)] = 2;
    return;
  }
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < vs.size(); ++i)
    covariance += (q[i] - cq) * (P.row(vs[i]).transpose() - cp).transpose();
  const Eigen::Matrix3d R = nearest_rotation(covariance);
  double largest = 0;
  for (size_t i = 0; i < vs.size(); ++i) {
    const Vector3d x = R * (P.row(vs[i]).transpose() - cp) + cq;
    largest = std::max(largest, (x - q[i]).norm());
    w.out.V.row(vs[i]) = x.transpose();
  }
  w.kind[static_cast<size_t>(e)] = 1;
  w.offset[static_cast<size_t>(e)] = largest / H;
}

// Element e's vertices set from the rows of X.
void set_element(Following& w, int e, const MatrixX3d& X) {
  for (const int f : w.faces[static_cast<size_t>(e)])
    for (int k = 0; k < 3; ++k) w.out.V.row(w.out.F(f, k)) = X.row(w.out.F(f, k));
}

// Rigid elements pressed into a neighbour follow the surface instead. Following the surface can
// fold an element through itself where the surface creases (the synthesis removes such elements
// too; kept rigid and shrunk instead, more go): it goes, or, kept whole (keep_elements), goes
// back to its rigid place. Returns the elements that changed.
std::vector<char> unbend_pressed(const FollowBaseOptions& options, ElementPairs& pairs_of,
                                 Following& w) {
  std::vector<char> active(static_cast<size_t>(w.elements), 0);
  // Only rigid elements can newly touch another: following, the surface keeps their gaps.
  for (int e = 0; e < w.elements; ++e)
    active[static_cast<size_t>(e)] =
        w.kind[static_cast<size_t>(e)] == 1 && !w.removed[static_cast<size_t>(e)];
  std::vector<char> changed(static_cast<size_t>(w.elements), 0);
  const MatrixX3d rigid = options.keep_elements ? w.out.V : MatrixX3d();
  for (const auto& [a, b] : pairs_of.intersecting(active, w.removed))
    for (const int e : {a, b})
      if (w.kind[static_cast<size_t>(e)] == 1 && !changed[static_cast<size_t>(e)]) {
        changed[static_cast<size_t>(e)] = 1;
        ++w.unbent;
        set_element(w, e, w.Q);
      }
  if (w.unbent > 0)
    for (const int e : pairs_of.self_intersecting(changed)) {
      if (!options.keep_elements) {
        w.removed[static_cast<size_t>(e)] = 1;
        continue;
      }
      --w.unbent;
      set_element(w, e, rigid);
    }
  return changed;
}

// What still intersects is shrunk about its centre, as the synthesis's post-processing does
// (95% down to 60%), and what even that does not free goes (the later element of each pair),
// unless kept (keep_elements: the pairs are counted).
void shrink_or_remove_pressed(const FollowBaseOptions& options, const std::vector<char>& changed,
                              ElementPairs& pairs_of, Following& w) {
  std::vector<std::pair<int, int>> pairs = pairs_of.intersecting(changed, w.removed);
  const MatrixX3d unshrunk = w.out.V;
  std::vector<char> pressed(static_cast<size_t>(w.elements), 0);
  for (const double scale : {0.95, 0.9, 0.85, 0.8, 0.7, 0.6}) {
    if (pairs.empty()) break;
    std::fill(pressed.begin(), pressed.end(), 0);
    for (const auto& [a, b] : pairs)
      pressed[static_cast<size_t>(a)] = pressed[static_cast<size_t>(b)] = 1;
    for (int e = 0; e < w.elements; ++e)
      if (pressed[static_cast<size_t>(e)]) pairs_of.scale(e, unshrunk, scale);
    pairs = pairs_of.intersecting(pressed, w.removed);
  }
  for (const auto& [a, b] : pairs)
    if (!options.keep_elements && !w.removed[static_cast<size_t>(a)])
      w.removed[static_cast<size_t>(b)] = 1;
  w.still_pressed = static_cast<int>(pairs.size());
  for (int e = 0; e < w.elements; ++e)
    w.shrunk += !w.removed[static_cast<size_t>(e)] && pairs_of.was_scaled(e);
}

FollowBaseStats following_stats(const FollowBaseOptions& options, const Following& w) {
  FollowBaseStats stats;
  stats.unbent = w.unbent;
  stats.shrunk = w.shrunk;
  stats.pressed_pairs = options.keep_elements ? w.still_pressed : 0;
  stats.removed = w.removed;
  stats.num_removed = static_cast<int>(std::count(w.removed.begin(), w.removed.end(), 1));
  stats.elements = w.elements;
  for (int e = 0; e < w.elements; ++e) {
    const char k = w.kind[static_cast<size_t>(e)];
    (k == 0 ? stats.unmoved : k == 1 ? stats.rigid : stats.following) += 1;
    stats.largest_rigid_offset =
        std::max(stats.largest_rigid_offset, w.offset[static_cast<size_t>(e)]);
  }
  return stats;
}

}  // namespace

TriMesh follow_base(const SavedQuilt& saved, const MatrixX3d& V, const FollowBaseOptions& options,
                    FollowBaseStats* stats) {
  options.validate();
  MQ_CHECK(V.rows() == saved.base.V.rows() && V.allFinite(), InvalidInput,
           "follow_base: ", V.rows(), " base positions for a welded base of ", saved.base.V.rows(),
           " vertices, or a position not finite");
  Following w;
  w.elements = connected_components(saved.output.F, saved.output.num_vertices(), w.face_component);
  w.faces = component_faces(w.face_component, w.elements);
  MQ_CHECK(options.remove.empty() || static_cast<int>(options.remove.size()) == w.elements,
           InvalidInput, "follow_base: ", options.remove.size(), " removal flags for ", w.elements,
           " elements");
  w.out = saved.output;
  w.Q = saved.output.V;
  w.kind.assign(static_cast<size_t>(w.elements), 0);
  w.offset.assign(static_cast<size_t>(w.elements), 0.0);
  const MatrixX3i& F = saved.base.F;
  const MatrixX3d N_rest = vertex_normals(saved.base.V, F), N = vertex_normals(V, F);
  tbb::parallel_for(0, w.elements,
                    [&](int e) { place_element(saved, V, N, N_rest, options, e, w); });
  w.removed = options.remove;
  w.removed.resize(static_cast<size_t>(w.elements), 0);
  if (options.resolve_intersections) {
    ElementPairs pairs_of(w.out, w.face_component, w.faces, w.elements);
    const std::vector<char> changed = unbend_pressed(options, pairs_of, w);
    shrink_or_remove_pressed(options, changed, pairs_of, w);
  }
  if (std::find(w.removed.begin(), w.removed.end(), 1) != w.removed.end())
    w.out = without_elements(w.out, w.face_component, w.removed);
  if (stats) *stats = following_stats(options, w);
  return std::move(w.out);
}

}  // namespace mq
