// Element deformation of mesh quilting (paper section 2.6, Eqs. (4)-(6)): a geometry element is
// bent towards positional constraints while its uniform Laplacian coordinates are preserved.
#pragma once

#include <Eigen/Sparse>
#include <array>
#include <vector>

#include "core/linear_constraint.h"
#include "core/mesh.h"

namespace mq {

// LinearConstraint (core/linear_constraint.h): weights of a constraint must sum to 1 (they
// are barycentric coordinates, possibly negative), which keeps the problem translation invariant.

struct DeformationOptions {
  double mu = 1.0;  // weight of the constraint term; the paper uses 1
};

// Uniform Laplacian of Eq. (4) as a sparse #V by #V matrix: L(i,i) = 1 and L(i,j) = -1/|N(i)|
// for each 1-ring neighbour j (edges of degenerate faces joining a vertex to itself are ignored).
// Rows of vertices without neighbours are zero.
//   F  #F by 3 vertex indices in [0, num_vertices)
// Throws InvalidInput for a negative num_vertices or an index out of range.
Eigen::SparseMatrix<double> uniform_laplacian(const MatrixX3i& F, int num_vertices);

// Precompute-then-query form of deform_element for an element deformed repeatedly with different
// constraint sets. Keeps L, delta = L V, L^T delta, the vertex components and a fill-reducing
// ordering of the pattern of L^T L, so that each solve only fills values and factorises.
// Each solve() is const and thread-safe.
class LaplacianDeformer {
 public:
  //   V  #V by 3 rest positions (finite)
  //   F  #F by 3 vertex indices in [0, #V)
  // Throws InvalidInput for a non-finite position, an index out of range, or mu not > 0.
  LaplacianDeformer(const MatrixX3d& V, const MatrixX3i& F, const DeformationOptions& options = {});

  // Minimises sum_i |L(w_i) - L(v_i)|^2 + mu sum_c |sum_k a_k w_{c,k} - target_c|^2 (Eqs. (5),
  // (6)) with the original, untransformed Laplacian coordinates, as the paper does. Connected
  // components that no constraint touches are excluded from the solve and keep their positions
  // exactly. Returns #V by 3 new positions.
  // Preconditions per constraint: vertex indices in [0, #V) (or -1 with weight 0), finite weights
  // summing to 1, finite target, all vertices with a non-zero weight in one connected component.
  // Throws InvalidInput when a precondition fails (naming the constraint), SolverFailure when the
  // factorisation fails.
  MatrixX3d solve(const std::vector<LinearConstraint>& constraints) const;

  int num_vertices() const { return static_cast<int>(V_.rows()); }
  int num_components() const { return num_components_; }
  // Connected component of each vertex (through the edges of F), #V.
  const std::vector<int>& vertex_components() const { return component_; }
  const Eigen::SparseMatrix<double>& laplacian() const { return L_; }
  // Laplacian coordinates delta = L V of the rest positions, #V by 3.
  const MatrixX3d& laplacian_coordinates() const { return delta_; }
  const DeformationOptions& options() const { return options_; }

 private:
  MatrixX3d V_;
  DeformationOptions options_;
  Eigen::SparseMatrix<double> L_;
  MatrixX3d delta_;
  Eigen::MatrixXd rhs_;  // P L^T delta, permuted, #V by 3
  std::vector<int> component_;
  int num_components_ = 0;
  std::vector<int> perm_;               // vertex i is unknown perm_[i] of the permuted system
  Eigen::SparseMatrix<double> system_;  // P (L^T L) P^T, upper triangle, with a full diagonal
};

// One-off form: LaplacianDeformer(V, F, options).solve(constraints). Same contract.
MatrixX3d deform_element(const MatrixX3d& V, const MatrixX3i& F,
                         const std::vector<LinearConstraint>& constraints,
                         const DeformationOptions& options = {});

// One element to deform: V (#V by 3) and F (#F by 3) are borrowed and must outlive the call.
struct DeformationJob {
  const MatrixX3d* V = nullptr;
  const MatrixX3i* F = nullptr;
  std::vector<LinearConstraint> constraints;
};

// Deforms independent elements in parallel with oneTBB (the per-element loop of section 2.6).
// Result j is exactly deform_element(*jobs[j].V, *jobs[j].F, jobs[j].constraints, options),
// whatever the thread count. Throws InvalidInput for a null V or F, and otherwise the exception
// of the lowest-index failing job.
std::vector<MatrixX3d> deform_elements(const std::vector<DeformationJob>& jobs,
                                       const DeformationOptions& options = {});

}  // namespace mq

namespace mq {

// Keeps a deformation local: returns point constraints holding in place every vertex farther
// than `rings` edges (1-ring hops) from the vertices the given constraints involve. Without them
// an element constrained only at one end (a long thread stitched at a seam) is free to swing
// about the constrained region, since Eq. (5) only preserves untransformed Laplacian coordinates.
// Components without any constraint are left alone (they do not move anyway).
std::vector<LinearConstraint> anchor_far_vertices(const MatrixX3d& V, const MatrixX3i& F,
                                                  const std::vector<LinearConstraint>& constraints,
                                                  int rings);

}  // namespace mq
