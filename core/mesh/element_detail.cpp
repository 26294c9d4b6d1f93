#include "core/mesh/element_detail.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <unordered_map>
#include <vector>

#include "core/common/errors.h"
#include "core/common/fnv1a.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/quadric_simplification.h"

namespace mq {

namespace {

// The first vertex (in index order) at each of the six extremes of an element's bounding box:
// kept, the box stays the same.
void add_box_extremes(const MatrixX3d& V, std::vector<int>& kept) {
  if (V.rows() == 0) return;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Index lo = 0, hi = 0;
    V.col(axis).minCoeff(&lo);
    V.col(axis).maxCoeff(&hi);
    kept.push_back(static_cast<int>(lo));
    kept.push_back(static_cast<int>(hi));
  }
}

// Copies of one element (same connectivity, same edge lengths: congruent, up to a mirror) are
// simplified alike, so that a periodic swatch stays periodic (the lattice of its elements,
// section 3.1's global layout, is found as before) and each distinct element is simplified once.
// Edge lengths agree to 1e-3 of the element's size: a swatch read from an OBJ of 6 significant
// digits has its copies' edges differ by up to 4e-5 of a ring's (the sample chain mail).
bool congruent(const TriMesh& a, const TriMesh& b) {
  if (a.V.rows() != b.V.rows() || a.F != b.F) return false;
  const double scale = 1e-3 * bounding_box(a.V).extent().norm();
  for (Eigen::Index f = 0; f < a.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = a.F(f, k), j = a.F(f, (k + 1) % 3);
      const double la = (a.V.row(i) - a.V.row(j)).norm(), lb = (b.V.row(i) - b.V.row(j)).norm();
      if (!(std::abs(la - lb) <= scale)) return false;
    }
  return true;
}

std::uint64_t connectivity_hash(const TriMesh& e) {
  std::uint64_t h = kFnv1aOffset;
  const Eigen::Index nv = e.V.rows();
  fnv1a(h, &nv, sizeof nv);
  fnv1a(h, e.F.data(), static_cast<std::size_t>(e.F.size()) * sizeof(int));
  return h;
}

// How an element is simplified: the input vertices and faces it keeps, the faces in kept
// vertices' numbering (QuadricSimplification's origin_vertex, origin_face, mesh.F).
struct Collapses {
  std::vector<int> origin_vertex, origin_face;
  MatrixX3i F;
};

Collapses simplify_element(const TriMesh& element, const std::vector<int>& kept,
                           const ElementDetailOptions& options) {
  QuadricSimplification s = simplify_to_share(element, options.detail, options.min_faces, kept);
  return {std::move(s.origin_vertex), std::move(s.origin_face), std::move(s.mesh.F)};
}

// An element with its group's collapses applied: its own positions, normals and kinds.
TriMesh apply(const TriMesh& element, const Collapses& c) {
  TriMesh out;
  out.F = c.F;
  out.V.resize(static_cast<Eigen::Index>(c.origin_vertex.size()), 3);
  const bool normals = element.N.rows() == element.V.rows() && element.N.rows() > 0;
  if (normals) out.N.resize(out.V.rows(), 3);
  for (size_t i = 0; i < c.origin_vertex.size(); ++i) {
    out.V.row(static_cast<Eigen::Index>(i)) = element.V.row(c.origin_vertex[i]);
    if (normals) out.N.row(static_cast<Eigen::Index>(i)) = element.N.row(c.origin_vertex[i]);
  }
  if (!element.face_kind.empty())
    for (const int f : c.origin_face) out.face_kind.push_back(element.face_kind[f]);
  return out;
}

// The elements one after the other, in swatch order, each with its group's collapses; kinds
// index the swatch's list as before (each element was cut from the swatch with it whole).
TriMesh assemble(const TriMesh& swatch, const std::vector<TriMesh>& elements,
                 const std::vector<int>& group, const std::vector<Collapses>& collapses) {
  const int count = static_cast<int>(elements.size());
  std::vector<TriMesh> reduced(elements.size());
  tbb::parallel_for(0, count, [&](int c) { reduced[c] = apply(elements[c], collapses[group[c]]); });
  Eigen::Index nv = 0, nf = 0;
  for (const TriMesh& e : reduced) nv += e.V.rows(), nf += e.F.rows();
  const bool normals = swatch.N.rows() == swatch.V.rows() && swatch.V.rows() > 0;
  TriMesh out;
  out.V.resize(nv, 3);
  out.F.resize(nf, 3);
  if (normals) out.N.resize(nv, 3);
  out.kinds = swatch.kinds;
  Eigen::Index v0 = 0, f0 = 0;
  for (const TriMesh& e : reduced) {
    out.V.middleRows(v0, e.V.rows()) = e.V;
    out.F.middleRows(f0, e.F.rows()) = e.F.array() + static_cast<int>(v0);
    if (normals) out.N.middleRows(v0, e.V.rows()) = e.N;
    out.face_kind.insert(out.face_kind.end(), e.face_kind.begin(), e.face_kind.end());
    v0 += e.V.rows(), f0 += e.F.rows();
  }
  return out;
}

// The pairs (a < b) of elements with intersecting faces.
std::set<std::pair<int, int>> element_pairs(const TriMesh& mesh,
                                            const std::vector<int>& face_component) {
  std::set<std::pair<int, int>> pairs;
  for (const auto& [f, g] : intersecting_face_pairs(mesh.V, mesh.F)) {
    const int a = face_component[f], b = face_component[g];
    pairs.insert({std::min(a, b), std::max(a, b)});
  }
  return pairs;
}

int median(std::vector<int> values) {
  if (values.empty()) return 0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// The elements at lower detail, in swatch order (reduce_element_detail below full detail): groups
// of congruent copies simplified once, each raised until nothing intersects that did not.
// out.groups and out.raised are set; after[c] receives element c's faces.
TriMesh reduce_elements(const TriMesh& swatch, const ElementDetailOptions& options,
                        const std::vector<int>& face_component,
                        const std::vector<std::vector<int>>& faces, ElementDetail& out,
                        std::vector<int>& after) {
  const int count = static_cast<int>(faces.size());
  std::vector<TriMesh> elements(static_cast<size_t>(count));
  tbb::parallel_for(0, count, [&](int c) { elements[c] = extract_faces(swatch, faces[c]); });

  // Groups of congruent copies, each led by its first element (in swatch order); the kept
  // vertices are every member's box extremes, so every copy keeps its box.
  std::vector<int> group(static_cast<size_t>(count), -1);
  std::vector<int> leaders;
  std::vector<std::vector<int>> kept;
  std::unordered_map<std::uint64_t, std::vector<int>> by_hash;  // hash -> group leaders
  for (int c = 0; c < count; ++c) {
    std::vector<int>& candidates = by_hash[connectivity_hash(elements[c])];
    for (const int leader : candidates)
      if (congruent(elements[leader], elements[c])) {
        group[c] = group[leader];
        break;
      }
    if (group[c] < 0) {
      group[c] = static_cast<int>(leaders.size());
      leaders.push_back(c);
      kept.emplace_back();
      candidates.push_back(c);
    }
    add_box_extremes(elements[c].V, kept[group[c]]);
  }
  for (std::vector<int>& k : kept) {
    std::sort(k.begin(), k.end());
    k.erase(std::unique(k.begin(), k.end()), k.end());
  }
  out.groups = static_cast<int>(leaders.size());

  // Coarse enough, a thin wire folds through itself or a chord on its inner side cuts into a
  // neighbour it hugs: such groups get more faces (x1.6 a round, up to their own) until nothing
  // intersects that did not at full detail.
  const std::set<std::pair<int, int>> touching = element_pairs(swatch, face_component);
  const std::vector<int> folded = self_intersecting_components(swatch.V, swatch.F);
  std::vector<double> share(leaders.size(), options.detail);
  std::vector<char> redo(leaders.size(), 1);
  std::vector<Collapses> collapses(leaders.size());
  TriMesh mesh;
  for (bool any = true; any;) {
    tbb::parallel_for(size_t(0), leaders.size(), [&](size_t g) {
      if (!redo[g]) return;
      ElementDetailOptions o = options;
      o.detail = share[g];
      collapses[g] = simplify_element(elements[leaders[g]], kept[g], o);
    });
    mesh = assemble(swatch, elements, group, collapses);
    // The element of each face: the elements one after the other, each its group's faces.
    std::vector<int> element_of;
    for (int c = 0; c < count; ++c) {
      after[static_cast<size_t>(c)] = static_cast<int>(collapses[group[c]].F.rows());
      element_of.insert(element_of.end(), static_cast<size_t>(after[c]), c);
    }
    std::fill(redo.begin(), redo.end(), 0);
    any = false;
    const auto raise = [&](int c) {
      const int g = group[c];
      if (redo[g] || share[g] >= 1) return;
      redo[g] = 1;
      any = true;
      share[g] = std::min(1.0, 1.6 * share[g]);
    };
    for (const auto& [a, b] : element_pairs(mesh, element_of))
      if (!touching.count({a, b})) raise(a), raise(b);
    for (const int c : self_intersecting_components(mesh.V, mesh.F))
      if (!std::binary_search(folded.begin(), folded.end(), c)) raise(c);
  }
  for (size_t g = 0; g < leaders.size(); ++g) out.raised += share[g] > options.detail;
  return mesh;
}

}  // namespace

QuadricSimplification simplify_to_share(const TriMesh& mesh, double share, int min_faces,
                                        const std::vector<int>& kept) {
  ElementDetailOptions checked;
  checked.detail = share;
  checked.min_faces = min_faces;
  checked.validate();
  const int faces = mesh.num_faces();
  QuadricSimplificationOptions q;
  // The face count, not the error, decides how far it goes: any error up to the piece's size.
  q.max_error = bounding_box(mesh.V, mesh.F).extent().norm();
  q.target_faces = std::max(static_cast<int>(std::ceil(share * faces)), std::min(faces, min_faces));
  if (q.target_faces >= faces) {  // the mesh as it is
    QuadricSimplification same;
    same.mesh = mesh;
    for (int v = 0; v < mesh.num_vertices(); ++v) same.origin_vertex.push_back(v);
    for (int f = 0; f < faces; ++f) same.origin_face.push_back(f);
    return same;
  }
  // The defaults: a coarser tube (6 of 12 sides) is reachable, and a larger turn or a lower
  // quality let a thin wire fold into itself (seen on the sample chain mail at 75 degrees).
  q.max_normal_turn_degrees = 45;
  q.min_quality = 0.3;
  q.kept_vertices = kept;
  return simplify_by_quadrics(mesh, q);
}

void ElementDetailOptions::validate() const {
  MQ_CHECK(detail > 0 && detail <= 1, InvalidInput,
           "detail: the share of each element's faces to keep must be in (0, 1], got ", detail);
  MQ_CHECK(min_faces >= 4, InvalidInput,
           "detail: the fewest faces of an element must be at least 4, got ", min_faces);
}

ElementDetail reduce_element_detail(const TriMesh& swatch, const ElementDetailOptions& options) {
  options.validate();
  const int nv = swatch.num_vertices();
  MQ_CHECK(swatch.F.rows() == 0 || (swatch.F.minCoeff() >= 0 && swatch.F.maxCoeff() < nv),
           InvalidInput, "detail: face index out of range [0, ", nv, ")");
  MQ_CHECK(swatch.V.allFinite(), InvalidInput, "detail: vertex positions are not finite");
  std::vector<int> face_component;
  const int count = connected_components(swatch.F, nv, face_component);
  const std::vector<std::vector<int>> faces = component_faces(face_component, count);
  ElementDetail out;
  out.elements = count;
  std::vector<int> before(faces.size());
  for (size_t c = 0; c < faces.size(); ++c) before[c] = static_cast<int>(faces[c].size());
  std::vector<int> after = before;
  out.mesh = options.detail == 1
                 ? swatch
                 : reduce_elements(swatch, options, face_component, faces, out, after);
  if (count > 0) {
    out.max_faces_before = *std::max_element(before.begin(), before.end());
    out.max_faces_after = *std::max_element(after.begin(), after.end());
  }
  out.median_faces_before = median(before);
  out.median_faces_after = median(after);
  return out;
}

}  // namespace mq
