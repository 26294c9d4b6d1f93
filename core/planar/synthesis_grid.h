// The 2D grid of paper section 2.3: the output domain (and the swatch) split into square cells of
// one size, each triangle assigned to the cells its footprint touches, and the seed rule: the
// next seed is the unprocessed cell with the most processed neighbours.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"
#include "core/planar/overlap_region.h"

namespace mq {

// Integer cell coordinates.
struct Cell {
  int x = 0, y = 0;
  bool operator==(const Cell& o) const { return x == o.x && y == o.y; }
};

class SynthesisGrid {
 public:
  // A grid of nx by ny cells of side cell_size with its (0,0) cell's corner at origin (x, y).
  // Throws InvalidInput for non-positive or non-finite sizes, or more than 2^26 cells.
  SynthesisGrid(const Vector2d& origin, double cell_size, int nx, int ny);

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int num_cells() const { return nx_ * ny_; }
  double cell_size() const { return cell_size_; }
  const Vector2d& origin() const { return origin_; }
  bool contains(const Cell& c) const { return c.x >= 0 && c.y >= 0 && c.x < nx_ && c.y < ny_; }
  int index(const Cell& c) const { return c.y * nx_ + c.x; }
  Cell cell(int index) const { return {index % nx_, index / nx_}; }
  // The cell containing point p (possibly outside the grid).
  Cell cell_of(double x, double y) const;

  bool processed(const Cell& c) const { return processed_[index(c)] != 0; }
  // A copy of the processed flags as a point predicate (points outside the grid: false), for
  // the overlapping region of the patch being merged (it must not see cells marked later).
  OverlapRegion::ProcessedTest processed_snapshot() const;
  void set_processed(const Cell& c) { processed_[index(c)] = 1; }
  int num_processed() const;

  // Section 2.3 seed rule over the 8-neighbourhood; ties go to the lowest (y, x) index so the
  // choice is deterministic. A grid with nothing processed yields cell (0, 0). Returns false
  // when every cell is processed.
  bool next_seed(Cell& seed) const;

  // Per-cell lists of the faces whose footprint bounding box touches the cell (paper: "each
  // triangle is assigned to the grid cells containing it"). Faces outside the grid are ignored.
  //   V #V by 3, F #F by 3; result has num_cells() lists.
  std::vector<std::vector<int>> assign_faces(const MatrixX3d& V, const MatrixX3i& F) const;

 private:
  Vector2d origin_;
  double cell_size_;
  int nx_, ny_;
  std::vector<unsigned char> processed_;
};

}  // namespace mq
