#include "core/mesh/element_kinds.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_set>
#include <utility>

#include "core/common/errors.h"
#include "core/common/fnv1a.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

bool has_kinds(const TriMesh& mesh) {
  return !mesh.kinds.empty() && mesh.face_kind.size() == static_cast<size_t>(mesh.F.rows());
}

void set_single_kind(TriMesh& mesh, const std::string& name) {
  mesh.kinds.assign(1, name);
  mesh.face_kind.assign(static_cast<size_t>(mesh.F.rows()), 0);
}

void ensure_kinds(TriMesh& mesh) {
  if (mesh.kinds.empty() || mesh.face_kind.empty()) {
    set_single_kind(mesh, kDefaultKind);
    return;
  }
  check_kinds(mesh);
}

void check_kinds(const TriMesh& mesh) {
  if (mesh.face_kind.empty()) return;
  MQ_CHECK(mesh.face_kind.size() == static_cast<size_t>(mesh.F.rows()), InvalidInput,
           "the mesh has ", mesh.face_kind.size(), " face kinds for ", mesh.F.rows(), " faces");
  const int n = static_cast<int>(mesh.kinds.size());
  for (const int k : mesh.face_kind)
    MQ_CHECK(k >= 0 && k < n, InvalidInput, "face kind ", k, " is not one of the ", n, " kinds");
}

std::vector<int> component_kinds(const TriMesh& mesh, const std::vector<int>& face_component,
                                 int num_components) {
  std::vector<int> kind(static_cast<size_t>(num_components), 0);
  if (!has_kinds(mesh)) return kind;
  // (component, kind) of every face, sorted: each component's longest run is its kind. Sorting
  // keeps this O(F log F) however many kinds a file names (one group per element is common).
  std::vector<std::pair<int, int>> ck(face_component.size());
  for (size_t f = 0; f < face_component.size(); ++f) ck[f] = {face_component[f], mesh.face_kind[f]};
  std::sort(ck.begin(), ck.end());
  std::vector<int> best(static_cast<size_t>(num_components), 0);
  for (size_t i = 0; i < ck.size();) {
    size_t j = i;
    while (j < ck.size() && ck[j] == ck[i]) ++j;
    const size_t c = static_cast<size_t>(ck[i].first);
    if (static_cast<int>(j - i) > best[c]) {  // runs come by ascending kind: ties keep the lowest
      best[c] = static_cast<int>(j - i);
      kind[c] = ck[i].second;
    }
    i = j;
  }
  return kind;
}

void remove_unused_kinds(TriMesh& mesh) {
  if (!has_kinds(mesh)) return;
  std::vector<int> used(mesh.kinds.size(), 0);
  for (const int k : mesh.face_kind) used[static_cast<size_t>(k)] = 1;
  std::vector<int> to(mesh.kinds.size(), -1);
  std::vector<std::string> kept;
  for (size_t k = 0; k < mesh.kinds.size(); ++k)
    if (used[k]) {
      to[k] = static_cast<int>(kept.size());
      kept.push_back(mesh.kinds[k]);
    }
  if (kept.size() == mesh.kinds.size()) return;
  for (int& k : mesh.face_kind) k = to[static_cast<size_t>(k)];
  mesh.kinds = std::move(kept);
}

int kind_index(std::vector<std::string>& kinds, const std::string& name) {
  const auto it = std::find(kinds.begin(), kinds.end(), name);
  if (it != kinds.end()) return static_cast<int>(it - kinds.begin());
  kinds.push_back(name);
  return static_cast<int>(kinds.size()) - 1;
}

std::string sanitized_kind(const std::string& name) {
  std::string s;
  for (const char c : name) s += (c > ' ' && c < 127 && c != '#') ? c : '_';
  return s.empty() ? std::string(kDefaultKind) : s;
}

std::vector<std::string> unique_kind_names(const std::vector<std::string>& kinds) {
  std::vector<std::string> names;
  names.reserve(kinds.size());
  std::unordered_set<std::string> taken;
  for (const std::string& kind : kinds) taken.insert(sanitized_kind(kind));
  std::unordered_set<std::string> used;
  for (const std::string& kind : kinds) {
    std::string name = sanitized_kind(kind);
    if (used.count(name)) {
      // A suffix no kind has as its own name, nor an earlier suffixed one.
      for (int n = 2;; ++n) {
        const std::string candidate = name + "_" + std::to_string(n);
        if (!taken.count(candidate) && !used.count(candidate)) {
          name = candidate;
          break;
        }
      }
    }
    used.insert(name);
    names.push_back(name);
  }
  return names;
}

ElementLabels element_labels(const TriMesh& mesh) {
  ElementLabels l;
  l.count = connected_components(mesh.F, mesh.num_vertices(), l.face_element);
  l.element_kind = component_kinds(mesh, l.face_element, l.count);
  l.vertex_element.assign(static_cast<size_t>(mesh.num_vertices()), 0);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      l.vertex_element[static_cast<size_t>(mesh.F(f, k))] = l.face_element[static_cast<size_t>(f)];
  l.kinds = has_kinds(mesh) ? mesh.kinds : std::vector<std::string>{kDefaultKind};
  return l;
}

KindMaterial kind_material(const std::string& kind) {
  KindMaterial m;
  if (kind == "ring") return {0.62, 0.63, 0.66, 1.0, 0.35};
  if (kind == "thread_x") return {0.80, 0.64, 0.42, 0.0, 0.85};
  if (kind == "thread_y") return {0.52, 0.36, 0.24, 0.0, 0.85};
  if (kind == "vine") return {0.30, 0.20, 0.12, 0.0, 0.8};
  if (kind == "leaf") return {0.16, 0.42, 0.10, 0.0, 0.55};
  if (kind == "apple") return {0.70, 0.10, 0.08, 0.0, 0.45};
  if (kind == kDefaultKind) return m;
  // color_RRGGBB: that colour (sRGB hex, given by `meshquilt edit --color`), stored linear.
  if (kind.size() == 12 && kind.compare(0, 6, "color_") == 0 &&
      kind.find_first_not_of("0123456789abcdefABCDEF", 6) == std::string::npos) {
    double* channel[3] = {&m.r, &m.g, &m.b};
    for (int c = 0; c < 3; ++c) {
      const double srgb =
          std::stoi(kind.substr(6 + 2 * static_cast<size_t>(c), 2), nullptr, 16) / 255.0;
      *channel[c] = srgb <= 0.04045 ? srgb / 12.92 : std::pow((srgb + 0.055) / 1.055, 2.4);
    }
    return m;
  }
  // A hue from the name at fixed saturation and value.
  std::uint64_t h = kFnv1aOffset;
  fnv1a(h, kind.data(), kind.size());
  const double hue = static_cast<double>(h % 360) / 60.0;
  const double x = 1 - std::abs(std::fmod(hue, 2.0) - 1);
  const double c = 0.55, lo = 0.15;
  const int sector = static_cast<int>(hue);
  const double rgb[6][3] = {{c, x * c, 0}, {x * c, c, 0}, {0, c, x * c},
                            {0, x * c, c}, {x * c, 0, c}, {c, 0, x * c}};
  m.r = lo + rgb[sector][0];
  m.g = lo + rgb[sector][1];
  m.b = lo + rgb[sector][2];
  return m;
}

}  // namespace mq
