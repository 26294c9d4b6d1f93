#include "core/shell/element_removal.h"

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/vertex_cover.h"
#include "core/shell/element_grid.h"

namespace mq {

namespace {

// Element k's mesh as V places it.
TriMesh placed_element(const SurfaceQuilt& quilt, const std::vector<Eigen::Index>& first,
                       const MatrixX3d& V, size_t k) {
  TriMesh m;
  m.V = V.middleRows(first[k], first[k + 1] - first[k]);
  m.F = quilt.elements[k].F;
  return m;
}

// Does m (element k's new placement, box b) clear every kept element near it?
bool clears_neighbours(const SurfaceQuilt& quilt, const std::vector<Eigen::Index>& first,
                       const MatrixX3d& V, const std::vector<char>& drop, const ElementGrid& grid,
                       size_t k, const TriMesh& m, const BoundingBox& b) {
  for (const int j : grid.near(b))
    if (static_cast<size_t>(j) != k && !drop[j] &&
        meshes_intersect(m, placed_element(quilt, first, V, static_cast<size_t>(j))))
      return false;
  return true;
}

BoundingBox box_of(const MatrixX3d& V) {
  BoundingBox b;
  for (Eigen::Index v = 0; v < V.rows(); ++v) b.extend(V.row(v).transpose());
  return b;
}

}  // namespace

void choose_removals(const std::vector<std::pair<int, int>>& pairs,
                     const std::vector<int>& element_of, std::vector<char>& drop,
                     std::vector<char>& folded) {
  for (const auto& [f, g] : pairs)
    if (element_of[f] == element_of[g]) folded[element_of[f]] = drop[element_of[f]] = 1;
  std::vector<std::pair<int, int>> touching;
  for (const auto& [f, g] : pairs)
    if (element_of[f] != element_of[g]) touching.emplace_back(element_of[f], element_of[g]);
  greedy_vertex_cover(touching, drop);
}

std::vector<char> try_layout_versions(const SurfaceQuilt& quilt,
                                      const std::vector<Eigen::Index>& first,
                                      const std::vector<char>& skip, const MatrixX3d& A,
                                      const std::vector<Eigen::Index>& alternative_first,
                                      MatrixX3d& V, std::vector<char>& drop) {
  const size_t ne = quilt.elements.size();
  std::vector<char> restored(ne, 0);
  if (A.rows() == 0) return restored;
  ElementGrid grid(V, first, drop);
  for (size_t k = 0; k < ne; ++k) {
    const Eigen::Index n = alternative_first[k + 1] - alternative_first[k];
    if (!drop[k] || skip[k] || n == 0 || n != first[k + 1] - first[k]) continue;
    TriMesh m;
    m.V = A.middleRows(alternative_first[k], n);
    m.F = quilt.elements[k].F;
    if (self_intersects(m.V, m.F)) continue;
    const BoundingBox b = box_of(m.V);
    if (!clears_neighbours(quilt, first, V, drop, grid, k, m, b)) continue;
    V.middleRows(first[k], n) = m.V;
    drop[k] = 0;
    grid.insert(static_cast<int>(k), b);
    restored[k] = 1;
  }
  return restored;
}

int shrink_to_fit(const SurfaceQuilt& quilt, const std::vector<Eigen::Index>& first,
                  const std::vector<char>& skip, MatrixX3d& V, std::vector<char>& drop) {
  const size_t ne = quilt.elements.size();
  ElementGrid grid(V, first, drop);
  int restored = 0;
  for (size_t k = 0; k < ne; ++k) {
    if (!drop[k] || skip[k] || first[k + 1] == first[k]) continue;
    const TriMesh original = placed_element(quilt, first, V, k);
    const Vector3d c = original.V.colwise().mean().transpose();
    for (const double factor : {0.95, 0.9, 0.85}) {
      TriMesh m = original;
      for (Eigen::Index v = 0; v < m.V.rows(); ++v)
        m.V.row(v) = (c + factor * (m.V.row(v).transpose() - c)).transpose();
      const BoundingBox b = box_of(m.V);
      if (!clears_neighbours(quilt, first, V, drop, grid, k, m, b)) continue;
      V.middleRows(first[k], m.V.rows()) = m.V;
      drop[k] = 0;
      grid.insert(static_cast<int>(k), b);
      ++restored;
      break;
    }
  }
  return restored;
}

}  // namespace mq
