#include "core/shell/element_editing.h"

#include <cmath>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

void ElementSelection::validate() const {
  for (const int id : ids) MQ_CHECK(id >= 0, InvalidInput, "element id ", id, " is negative");
  MQ_CHECK(!sphere || (centre.allFinite() && std::isfinite(radius) && radius > 0), InvalidInput,
           "a sphere needs a finite centre and a positive radius, got ", radius);
  MQ_CHECK(!box || (lo.allFinite() && hi.allFinite() && (lo.array() <= hi.array()).all()),
           InvalidInput, "a box needs finite corners, the first no larger than the second");
}

std::vector<char> select_elements(const SavedQuilt& quilt, const ElementSelection& s) {
  s.validate();
  const TriMesh& out = quilt.output;
  std::vector<int> face_component;
  const int elements = connected_components(out.F, out.num_vertices(), face_component);
  const std::vector<int> kind = component_kinds(out, face_component, elements);
  std::vector<char> chosen(static_cast<size_t>(elements), 1);
  if (!s.ids.empty()) {
    std::vector<char> listed(static_cast<size_t>(elements), 0);
    for (const int id : s.ids) {
      MQ_CHECK(id < elements, InvalidInput, "element id ", id, " is beyond the quilt's ", elements,
               " elements (0 to ", elements - 1, ")");
      listed[static_cast<size_t>(id)] = 1;
    }
    for (int e = 0; e < elements; ++e)
      chosen[static_cast<size_t>(e)] &= listed[static_cast<size_t>(e)];
  }
  if (!s.kind.empty()) {
    int k = -1;
    std::string names;
    for (size_t i = 0; i < out.kinds.size(); ++i) {
      if (out.kinds[i] == s.kind) k = static_cast<int>(i);
      names += (i ? ", " : "") + out.kinds[i];
    }
    MQ_CHECK(k >= 0, InvalidInput, "the quilt has no kind '", s.kind,
             "' (its kinds: ", names.empty() ? std::string("none") : names, ")");
    for (int e = 0; e < elements; ++e)
      chosen[static_cast<size_t>(e)] &= kind[static_cast<size_t>(e)] == k;
  }
  if (s.sphere || s.box) {
    std::vector<Vector3d> sum(static_cast<size_t>(elements), Vector3d::Zero());
    std::vector<int> count(static_cast<size_t>(elements), 0);
    std::vector<int> vertex_element(static_cast<size_t>(out.num_vertices()), -1);
    for (int f = 0; f < out.num_faces(); ++f)
      for (int k = 0; k < 3; ++k)
        vertex_element[static_cast<size_t>(out.F(f, k))] = face_component[static_cast<size_t>(f)];
    for (int v = 0; v < out.num_vertices(); ++v)
      if (const int e = vertex_element[static_cast<size_t>(v)]; e >= 0) {
        sum[static_cast<size_t>(e)] += out.V.row(v).transpose();
        ++count[static_cast<size_t>(e)];
      }
    for (int e = 0; e < elements; ++e) {
      const Vector3d c = sum[static_cast<size_t>(e)] / std::max(1, count[static_cast<size_t>(e)]);
      if (s.sphere) chosen[static_cast<size_t>(e)] &= (c - s.centre).norm() <= s.radius;
      if (s.box)
        chosen[static_cast<size_t>(e)] &=
            (c.array() >= s.lo.array()).all() && (c.array() <= s.hi.array()).all();
    }
  }
  return chosen;
}

TriMesh without_elements(const TriMesh& out, const std::vector<int>& face_component,
                         const std::vector<char>& chosen, std::vector<int>* vertex_map_out) {
  // Kept faces in order, kept vertices in order (ids, and the vertices of every element kept,
  // stay as they were).
  TriMesh kept;
  kept.kinds = out.kinds;
  std::vector<int> new_index(static_cast<size_t>(out.num_vertices()), -1);
  int faces = 0;
  for (int f = 0; f < out.num_faces(); ++f)
    if (!chosen[static_cast<size_t>(face_component[static_cast<size_t>(f)])]) {
      ++faces;
      for (int k = 0; k < 3; ++k) new_index[static_cast<size_t>(out.F(f, k))] = 0;
    }
  std::vector<int> vertex_map;
  for (int v = 0; v < out.num_vertices(); ++v)
    if (new_index[static_cast<size_t>(v)] == 0) {
      new_index[static_cast<size_t>(v)] = static_cast<int>(vertex_map.size());
      vertex_map.push_back(v);
    }
  kept.F.resize(faces, 3);
  for (int f = 0, g = 0; f < out.num_faces(); ++f)
    if (!chosen[static_cast<size_t>(face_component[static_cast<size_t>(f)])]) {
      for (int k = 0; k < 3; ++k) kept.F(g, k) = new_index[static_cast<size_t>(out.F(f, k))];
      if (!out.face_kind.empty()) kept.face_kind.push_back(out.face_kind[static_cast<size_t>(f)]);
      ++g;
    }
  kept.V.resize(static_cast<Eigen::Index>(vertex_map.size()), 3);
  for (size_t i = 0; i < vertex_map.size(); ++i)
    kept.V.row(static_cast<Eigen::Index>(i)) = out.V.row(vertex_map[i]);
  if (vertex_map_out) *vertex_map_out = std::move(vertex_map);
  return kept;
}

void remove_elements(SavedQuilt& quilt, const std::vector<char>& chosen) {
  TriMesh& out = quilt.output;
  std::vector<int> face_component;
  const int elements = connected_components(out.F, out.num_vertices(), face_component);
  MQ_CHECK(static_cast<int>(chosen.size()) == elements, InvalidInput,
           "remove_elements: ", chosen.size(), " flags for ", elements, " elements");
  std::vector<int> vertex_map;
  TriMesh kept = without_elements(out, face_component, chosen, &vertex_map);
  LocalCoordinates coords;
  const auto n = static_cast<Eigen::Index>(vertex_map.size());
  coords.face.resize(n);
  coords.bary.resize(n, 3);
  coords.height.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int v = vertex_map[static_cast<size_t>(i)];
    coords.face(i) = quilt.coords.face(v);
    coords.bary.row(i) = quilt.coords.bary.row(v);
    coords.height(i) = quilt.coords.height(v);
  }
  remove_unused_kinds(kept);
  out = std::move(kept);
  quilt.coords = std::move(coords);
}

namespace {

// Sets the kind of every face of element e to k (face_kind made #F first).
void set_kinds(TriMesh& out, const std::vector<int>& face_component,
               const std::vector<int>& element_kind) {
  ensure_kinds(out);
  for (int f = 0; f < out.num_faces(); ++f)
    if (const int k = element_kind[static_cast<size_t>(face_component[static_cast<size_t>(f)])];
        k >= 0)
      out.face_kind[static_cast<size_t>(f)] = k;
  remove_unused_kinds(out);
}

}  // namespace

void set_element_kind(SavedQuilt& quilt, const std::vector<char>& chosen, const std::string& name) {
  TriMesh& out = quilt.output;
  std::vector<int> face_component;
  const int elements = connected_components(out.F, out.num_vertices(), face_component);
  MQ_CHECK(static_cast<int>(chosen.size()) == elements, InvalidInput,
           "set_element_kind: ", chosen.size(), " flags for ", elements, " elements");
  ensure_kinds(out);
  const int k = kind_index(out.kinds, name);
  std::vector<int> element_kind(static_cast<size_t>(elements), -1);
  for (int e = 0; e < elements; ++e)
    if (chosen[static_cast<size_t>(e)]) element_kind[static_cast<size_t>(e)] = k;
  set_kinds(out, face_component, element_kind);
}

void assign_palette(SavedQuilt& quilt, const std::vector<char>& chosen, int count,
                    std::uint64_t seed) {
  MQ_CHECK(count >= 1 && count <= 256, InvalidInput, "a palette of ", count,
           " looks: give 1 to 256");
  TriMesh& out = quilt.output;
  std::vector<int> face_component;
  const int elements = connected_components(out.F, out.num_vertices(), face_component);
  MQ_CHECK(static_cast<int>(chosen.size()) == elements, InvalidInput,
           "assign_palette: ", chosen.size(), " flags for ", elements, " elements");
  ensure_kinds(out);
  const std::vector<int> kind = component_kinds(out, face_component, elements);
  // A 64-bit generator's raw output modulo count: the same draws on every platform (the
  // standard distributions are not specified bit for bit).
  std::mt19937_64 rng(seed);
  std::vector<int> element_kind(static_cast<size_t>(elements), -1);
  for (int e = 0; e < elements; ++e) {
    if (!chosen[static_cast<size_t>(e)]) continue;
    const auto pick = static_cast<int>(rng() % static_cast<std::uint64_t>(count));
    element_kind[static_cast<size_t>(e)] =
        kind_index(out.kinds, out.kinds[static_cast<size_t>(kind[static_cast<size_t>(e)])] + "_" +
                                  std::to_string(pick + 1));
  }
  set_kinds(out, face_component, element_kind);
}

}  // namespace mq
