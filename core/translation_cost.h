// Translation cost of placing the swatch over an output sub-patch (paper section 2.4,
// Eqs. (1)-(3)): for every candidate translation t,
//   E(t) = sum over output points v of min over swatch faces f of
//          (1 + lambda * Dist(v, f + t)) * (1 + |n(v) - n(f)|).
// Dist(v, f + t) is evaluated as Dist(v - t, f) so that the swatch is never moved.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace mq {

// One cost evaluation: output points with their unit normals, and the translations to try.
//   points         #P by 3 output sub-patch vertices (finite)
//   point_normals  #P by 3 unit vertex normals (finite)
//   offsets        #T by 3 candidate translations of the swatch (finite; usually t_z = 0)
//   lambda         distance weight of Eq. (1), finite and >= 0 (the paper uses 1)
struct TranslationCostProblem {
  MatrixX3d points;
  MatrixX3d point_normals;
  MatrixX3d offsets;
  double lambda = 1.0;
};

// Throws InvalidInput when the problem breaks the preconditions above (row counts differ,
// NaN/inf entries, negative or non-finite lambda).
void validate_translation_cost_problem(const TranslationCostProblem& problem);

// The swatch side of Eq. (2), precomputed once and queried for many points: a uniform grid whose
// cells list every face whose bounding box meets them. Each listing ("entry") carries its own
// copy of the face's corners, unit normal and bounding sphere, in cell order, so that a query
// streams through memory instead of chasing face indices. The flat arrays are laid out for
// direct upload to an OpenCL device.
class SwatchDistanceGrid {
 public:
  // V #V by 3 swatch vertices, F #F by 3 faces (at least one), cell_size > 0 or 0 for an
  // automatic size (about twice the mean edge length, enlarged to keep #cells <= 2 #F + 64).
  // Throws InvalidInput on non-finite vertices, out-of-range indices, no faces, a negative
  // or non-finite cell size, or a cell size so small the grid would exceed 2^26 cells.
  SwatchDistanceGrid(const MatrixX3d& V, const MatrixX3i& F, double cell_size = 0.0);

  // min over faces f of (1 + lambda * Dist(q, f)) * (1 + |n - n(f)|): Eq. (2) for the
  // query point q = v - t. Exact: cells are visited ring by ring around q's cell and the
  // search stops once a ring's distance lower bound d satisfies 1 + lambda * d >= best,
  // which no face beyond can beat because the normal factor is >= 1. Within the rings a cell
  // is skipped when the distance to the box of its faces' parts times its normal-cone bound
  // cannot beat best; an entry when its normal factor (tested without a square root) times
  // that distance bound cannot, or when its bounding sphere's distance cannot; only then is
  // the exact point-triangle distance computed.
  double min_face_cost(const Vector3d& q, const Vector3d& n, double lambda) const;

  int num_faces() const { return num_faces_; }
  int num_cells() const { return dims_.prod(); }
  int num_entries() const { return static_cast<int>(cell_faces_.size()); }
  const Vector3d& origin() const { return origin_; }
  double cell_size() const { return cell_size_; }
  // Cells per axis; cell (ix, iy, iz) has index (iz * ny + iy) * nx + ix.
  const Eigen::Vector3i& dims() const { return dims_; }
  // #cells + 1: the entries of cell c are [cell_start()[c], cell_start()[c + 1]).
  const std::vector<int>& cell_start() const { return cell_start_; }
  // #entries: the face index of each entry.
  const std::vector<int>& cell_faces() const { return cell_faces_; }
  // #entries * 9: the corners a, b, c of each entry's face.
  const std::vector<double>& entry_triangles() const { return entry_triangles_; }
  // #entries * 4: unit face normal (zero for a degenerate face) and 0 padding.
  const std::vector<double>& entry_normals() const { return entry_normals_; }
  // #entries * 4: a sphere (centre, radius) holding the face.
  const std::vector<double>& entry_spheres() const { return entry_spheres_; }
  // #cells * 8: per cell the box (min xyz, 0, max xyz, 0) of the parts of its faces' bounding
  // boxes inside the cell (empty cells: an inverted box, never read).
  const std::vector<double>& cell_boxes() const { return cell_boxes_; }
  // #cells * 4: per cell a direction c and radius r with |n(f) - c| <= r for its faces, so
  // |n - n(f)| >= |n - c| - r bounds the normal factor of the whole cell.
  const std::vector<double>& cell_normal_cones() const { return cell_cones_; }
  // A 64-bit hash of all the arrays above: equal grids have equal fingerprints, so device-side
  // copies can be cached by it.
  std::uint64_t fingerprint() const { return fingerprint_; }

 private:
  int num_faces_ = 0;
  Vector3d origin_ = Vector3d::Zero();
  double cell_size_ = 1.0;
  Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
  std::vector<int> cell_start_;
  std::vector<int> cell_faces_;
  std::vector<double> entry_triangles_;
  std::vector<double> entry_normals_;
  std::vector<double> entry_spheres_;
  std::vector<double> cell_boxes_;
  std::vector<double> cell_cones_;
  std::uint64_t fingerprint_ = 0;
};

// The interface shared by the CPU and OpenCL evaluators.
class TranslationCostEvaluator {
 public:
  virtual ~TranslationCostEvaluator() = default;
  // Returns #T costs E(t) (Eq. 3); all zero when there are no points, empty when there are no
  // offsets. Throws InvalidInput (see validate_translation_cost_problem); DeviceError for
  // device failures.
  virtual Eigen::VectorXd evaluate(const SwatchDistanceGrid& grid,
                                   const TranslationCostProblem& problem) = 0;
  virtual std::string name() const = 0;
};

// CPU path: TBB parallel over (offset, point) pairs, each writing its own slot; the per-offset
// sums then run in point order, so the result does not depend on the thread count.
class TranslationCostCpu final : public TranslationCostEvaluator {
 public:
  Eigen::VectorXd evaluate(const SwatchDistanceGrid& grid,
                           const TranslationCostProblem& problem) override;
  std::string name() const override { return "cpu"; }
};

// Reference: every face for every (t, v), O(#T #P #F); same summation order as the fast paths.
// V #V by 3, F #F by 3 (at least one face). Throws InvalidInput like the evaluators.
Eigen::VectorXd translation_cost_brute_force(const MatrixX3d& V, const MatrixX3i& F,
                                             const TranslationCostProblem& problem);

// Index of the smallest cost with a fixed tie rule: costs within relative 1e-6 of the minimum
// count as equal and the smallest such index wins, so that paths whose sums differ by
// rounding choose the same offset. Throws InvalidInput when costs is empty or has a NaN.
int best_offset(const Eigen::VectorXd& costs);

}  // namespace mq
