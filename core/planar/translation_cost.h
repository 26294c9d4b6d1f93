// Translation cost of placing the swatch over an output sub-patch (paper section 2.4,
// Eqs. (1)-(3)): for every candidate translation t,
//   E(t) = sum over output points v of min over swatch faces f of
//          (1 + lambda * Dist(v, f + t)) * (1 + |n(v) - n(f)|).
// Dist(v, f + t) is evaluated as Dist(v - t, f) so that the swatch is never moved.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"

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

// The swatch side of Eq. (2), precomputed once and queried for many points: a bounding volume
// hierarchy over the swatch faces whose nodes carry the box of their faces and a cone holding
// their unit normals, so that one bound prunes both factors of Eq. (1) for a whole subtree. The
// faces ("entries") are stored in leaf order with their own copies of corners, unit normal and
// bounding sphere, so that a leaf streams through memory. The flat arrays are laid out for
// direct upload to an OpenCL device. (A uniform grid scanned ~285 entries per query on the ivy
// swatch, whose leaves are dense and whose gaps are wide; see core/planar/translation_cost.cpp.)
class SwatchFaceTree {
 public:
  // Deepest tree the traversal's fixed stack (kernels/translation_cost.cl) supports.
  static constexpr int kMaxDepth = 48;

  // V #V by 3 swatch vertices, F #F by 3 faces (at least one); leaves hold at most leaf_size
  // faces (>= 1). Median splits along the longest axis of the face centroids, ties by face
  // index: deterministic. Throws InvalidInput on non-finite vertices, out-of-range indices, no
  // faces or leaf_size < 1.
  // Large leaves: a leaf's entries are cheap to scan, an inner node's two box tests are not
  // (matching time on the ivy wall / chain mail over the bunny, leaves of 8: 1.4x / 1.6x of
  // leaves of 64; 64 vs the former grid: 0.78x / 0.55x).
  SwatchFaceTree(const MatrixX3d& V, const MatrixX3i& F, int leaf_size = 64);

  // min over faces f of (1 + lambda * Dist(q, f)) * (1 + |n - n(f)|): Eq. (2) for the query
  // point q = v - t. Exact: depth first, nearer child first, a subtree is skipped when the
  // distance to its box alone cannot beat the best so far (compared squared), a leaf also when
  // that distance times its normal-cone bound cannot; in a leaf an entry is skipped when its
  // normal factor (tested without a square root) times the leaf's distance bound cannot, or when
  // its bounding sphere's distance cannot; only then is the exact point-triangle distance
  // computed.
  // entry (optional): receives the entry (leaf-order face slot, see entry_faces()) attaining
  // the minimum, -1 when there is none.
  // max_distance (>= 0): only faces within this distance of q compete (infinity, and -1 in
  // entry, when there is none); the cap also bounds the search, so a small one makes it cheap.
  // hint (optional, -1 = none): an entry likely to be near the minimum (the one a nearby point
  // or an earlier, slightly different query attained). Its cost starts the search as the best
  // so far, so the bounds prune from the first node on. The minimum returned is the same with
  // or without it; only among faces of exactly equal cost may the entry differ (the hint wins
  // such a tie).
  double min_face_cost(const Vector3d& q, const Vector3d& n, double lambda, int* entry = nullptr,
                       double max_distance = std::numeric_limits<double>::infinity(),
                       int hint = -1) const;
  // The Eq. (1) cost of one entry's face for query point q, bitwise the value min_face_cost
  // computes for it (so a sum of entry costs bounds a sum of minima exactly).
  // Precondition: 0 <= entry < num_faces() (InternalError otherwise).
  double entry_cost(int entry, const Vector3d& q, const Vector3d& n, double lambda) const;
  // The two factors of entry_cost apart, for a point kept on one entry while q moves (the
  // normal factor does not depend on q): entry_cost(entry, q, n, lambda) is bitwise
  // entry_cost_with_factor(entry, q, entry_normal_factor(entry, n), lambda).
  // Precondition: 0 <= entry < num_faces() (InternalError otherwise).
  double entry_normal_factor(int entry, const Vector3d& n) const;
  double entry_cost_with_factor(int entry, const Vector3d& q, double normal_factor,
                                double lambda) const;
  // Unit normal of an entry's face (zero for a degenerate face).
  Vector3d entry_normal(int entry) const;
  // The point of an entry's face closest to q, with its barycentric weights on the face's
  // corners in F's order (core/mesh/point_triangle.h).
  struct FacePoint {
    Vector3d barycentric;
    Vector3d point;
  };
  FacePoint entry_closest_point(int entry, const Vector3d& q) const;

  int num_faces() const { return static_cast<int>(entry_faces_.size()); }
  int num_nodes() const { return static_cast<int>(node_links_.size() / 2); }
  int depth() const { return depth_; }
  // #nodes * 2, nodes in depth-first order (the left child of an inner node i is i + 1):
  // inner node (right child, 0); leaf (-1 - first entry, number of entries).
  const std::vector<int>& node_links() const { return node_links_; }
  // #nodes * 8: per node the box (min xyz, 0, max xyz, 0) of its faces.
  const std::vector<double>& node_boxes() const { return node_boxes_; }
  // #nodes * 4: per node a direction c and radius r with |n(f) - c| <= r for its faces, so
  // |n - n(f)| >= |n - c| - r bounds the normal factor of the whole subtree.
  const std::vector<double>& node_cones() const { return node_cones_; }
  // #F: the face index of each entry (a permutation of the faces).
  const std::vector<int>& entry_faces() const { return entry_faces_; }
  // #F * 9: the corners a, b, c of each entry's face.
  const std::vector<double>& entry_triangles() const { return entry_triangles_; }
  // #F * 4: unit face normal (zero for a degenerate face) and 0 padding.
  const std::vector<double>& entry_normals() const { return entry_normals_; }
  // #F * 4: a sphere (centre, radius) holding the face.
  const std::vector<double>& entry_spheres() const { return entry_spheres_; }
  // Subtracted from every distance lower bound so that rounding never lets one exceed a true
  // distance (1e-9 of the swatch's box size).
  double query_slack() const { return slack_; }
  // A 64-bit hash of all the arrays above: equal trees have equal fingerprints, so device-side
  // copies can be cached by it.
  std::uint64_t fingerprint() const { return fingerprint_; }

 private:
  class Query;  // one min_face_cost search
  // The constructor's steps: the nodes over the faces (reordering `order` into leaf order), the
  // entries' copies of the faces in that order, the fingerprint.
  void build_nodes(const MatrixX3d& lo, const MatrixX3d& hi, const MatrixX3d& centroid,
                   const MatrixX3d& FN, std::vector<int>& order, int leaf_size);
  void copy_entries(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& FN,
                    const std::vector<int>& order, double scale);
  void take_fingerprint();

  int depth_ = 0;
  double slack_ = 0;
  std::vector<int> node_links_;
  std::vector<double> node_boxes_;
  std::vector<double> node_cones_;
  std::vector<int> entry_faces_;
  std::vector<double> entry_triangles_;
  std::vector<double> entry_normals_;
  std::vector<double> entry_spheres_;
  // The entries' unit normals again, one array per coordinate: the leaf scan's first pass
  // tests a block of them at once.
  std::vector<double> normal_x_, normal_y_, normal_z_;
  std::uint64_t fingerprint_ = 0;
};

// The interface shared by the CPU and OpenCL evaluators.
class TranslationCostEvaluator {
 public:
  virtual ~TranslationCostEvaluator() = default;
  // Returns #T costs E(t) (Eq. 3); all zero when there are no points, empty when there are no
  // offsets. Throws InvalidInput (see validate_translation_cost_problem); DeviceError for
  // device failures.
  virtual Eigen::VectorXd evaluate(const SwatchFaceTree& tree,
                                   const TranslationCostProblem& problem) = 0;
  // The `keep` offsets of least E(t), as indices into problem.offsets in ascending order: those
  // a stable sort of evaluate()'s costs puts first (ties to the lower index); every offset when
  // there are no more than `keep`. point_offsets: (point, offset) pairs actually evaluated.
  // This default evaluates every pair; a path may stop summing an offset once its partial sum
  // shows it cannot be kept (the choice is the same). Throws InvalidInput for keep < 1 or a
  // problem evaluate() refuses.
  struct LeastCostOffsets {
    std::vector<int> kept;
    long long point_offsets = 0;
  };
  virtual LeastCostOffsets least_cost_offsets(const SwatchFaceTree& tree,
                                              const TranslationCostProblem& problem, int keep);
  virtual std::string name() const = 0;
};

// CPU path: TBB parallel over (offset, point) pairs, each writing its own slot; the per-offset
// sums then run in point order, so the result does not depend on the thread count.
class TranslationCostCpu final : public TranslationCostEvaluator {
 public:
  Eigen::VectorXd evaluate(const SwatchFaceTree& tree,
                           const TranslationCostProblem& problem) override;
  // Offsets in fixed batches, each batch's offsets in parallel and each offset's points in
  // order; an offset is dropped as soon as its partial sum plus 1 per remaining point (every
  // minimum of Eq. (2) is at least 1) exceeds the keep-th least sum of the batches before.
  // The batches and the bound do not depend on the thread count, so neither does the result.
  LeastCostOffsets least_cost_offsets(const SwatchFaceTree& tree,
                                      const TranslationCostProblem& problem, int keep) override;
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
