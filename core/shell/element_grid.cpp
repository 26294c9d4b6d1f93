#include "core/shell/element_grid.h"

#include <algorithm>

#include "core/mesh/geometry_measures.h"

namespace mq {

ElementGrid::ElementGrid(const MatrixX3d& V, const std::vector<Eigen::Index>& first,
                         const std::vector<char>& skip) {
  const size_t ne = first.size() - 1;
  box.resize(ne);
  std::vector<double> sizes;
  for (size_t k = 0; k < ne; ++k) {
    for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) box[k].extend(V.row(v).transpose());
    if (first[k + 1] > first[k]) sizes.push_back(box[k].extent().maxCoeff());
  }
  if (sizes.empty()) return;
  std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
  cell_ = std::max(sizes[sizes.size() / 2], 1e-12);
  origin_ = bounding_box(V).min;
  for (size_t k = 0; k < ne; ++k)
    if (!skip[k] && first[k + 1] > first[k]) insert(static_cast<int>(k), box[k]);
}

void ElementGrid::insert(int k, const BoundingBox& b) {
  box[static_cast<size_t>(k)] = b;
  for_cells(b, [&](unsigned long long c) { grid_[c].push_back(k); });
}

std::vector<int> ElementGrid::near(const BoundingBox& b) const {
  std::vector<int> found;
  for_cells(b, [&](unsigned long long c) {
    if (const auto it = grid_.find(c); it != grid_.end())
      for (const int j : it->second)
        if (overlap(b, box[static_cast<size_t>(j)])) found.push_back(j);
  });
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

bool ElementGrid::overlap(const BoundingBox& a, const BoundingBox& b) {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

template <class Visit>
void ElementGrid::for_cells(const BoundingBox& b, Visit&& visit) const {
  if (grid_.empty() && cell_ == 0) return;
  const auto cell_of = [&](const Vector3d& p) {
    return ((p - origin_) / cell_).array().floor().cast<long long>().eval();
  };
  const auto lo = cell_of(b.min), hi = cell_of(b.max);
  // Cells hashed: the grid holds only the cells that elements occupy.
  for (long long x = lo(0); x <= hi(0); ++x)
    for (long long y = lo(1); y <= hi(1); ++y)
      for (long long z = lo(2); z <= hi(2); ++z)
        visit(static_cast<unsigned long long>(x) * 0x9E3779B97F4A7C15ull ^
              static_cast<unsigned long long>(y) * 0xC2B2AE3D27D4EB4Full ^
              static_cast<unsigned long long>(z) * 0x165667B19E3779F9ull);
}

}  // namespace mq
