// Elements' bounding boxes in a uniform grid, to find the elements near a box in about constant
// time (the embedding's repairs test each moved element against its neighbours only).
#pragma once

#include <unordered_map>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

class ElementGrid {
 public:
  // The elements' vertices are the rows [first[k], first[k + 1]) of V (#V by 3; first has
  // #elements + 1 ascending offsets). The cell is the median element's largest box side (a box
  // larger than a few cells is rare). Elements with skip[k] set (#elements flags), or with no
  // vertices, are left out until insert()ed. Throws nothing.
  ElementGrid(const MatrixX3d& V, const std::vector<Eigen::Index>& first,
              const std::vector<char>& skip);

  // Adds element k with box b (replacing its box). k in [0, #elements).
  void insert(int k, const BoundingBox& b);

  // The inserted elements whose box meets b, ascending.
  std::vector<int> near(const BoundingBox& b) const;

  // Do the closed boxes a and b meet?
  static bool overlap(const BoundingBox& a, const BoundingBox& b);

  // #elements boxes (empty for an element without vertices).
  std::vector<BoundingBox> box;

 private:
  template <class Visit>
  void for_cells(const BoundingBox& b, Visit&& visit) const;

  double cell_ = 0;
  Vector3d origin_ = Vector3d::Zero();
  std::unordered_map<unsigned long long, std::vector<int>> grid_;
};

}  // namespace mq
