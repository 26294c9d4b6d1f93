// Element deformation of mesh quilting (paper section 2.6, Eqs. (4)-(6)): a geometry element is
// bent towards positional constraints while its uniform Laplacian coordinates are preserved.
#pragma once

#include <Eigen/Sparse>
#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/planar/linear_constraint.h"

namespace mq {

// LinearConstraint (core/planar/linear_constraint.h): weights of a constraint must sum to 1 (they
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

// The part of the deformation precompute that depends only on the faces: L, the vertex
// components, a fill-reducing ordering of the pattern of L^T L and that matrix permuted. Every
// copy of a swatch element (translated, bent, in another patch) shares it.
class LaplacianTopology {
 public:
  //   F             #F by 3 vertex indices in [0, num_vertices)
  // Throws InvalidInput for a negative num_vertices or an index out of range.
  LaplacianTopology(const MatrixX3i& F, int num_vertices);

  int num_vertices() const { return static_cast<int>(L_.rows()); }
  const MatrixX3i& faces() const { return F_; }
  const Eigen::SparseMatrix<double>& laplacian() const { return L_; }
  int num_components() const { return num_components_; }
  const std::vector<int>& vertex_components() const { return component_; }
  // Vertex i is unknown permutation()[i] of the permuted system.
  const std::vector<int>& permutation() const { return perm_; }
  // P (L^T L) P^T, upper triangle, with every diagonal entry stored.
  const Eigen::SparseMatrix<double>& permuted_normal_matrix() const { return system_; }

 private:
  MatrixX3i F_;
  Eigen::SparseMatrix<double> L_;
  std::vector<int> component_;
  int num_components_ = 0;
  std::vector<int> perm_;
  Eigen::SparseMatrix<double> system_;
};

// Topologies of elements known in advance (a swatch's), looked up by their faces so that the
// copies of an element skip the ordering and the products. Filled before use, then read-only:
// find() is thread-safe.
class LaplacianTopologyCache {
 public:
  // Adds the topology of F (#F by 3) over num_vertices vertices, unless an equal one is held.
  // Throws like LaplacianTopology.
  void add(const MatrixX3i& F, int num_vertices);
  // The held topology with exactly these faces and vertex count, or null.
  std::shared_ptr<const LaplacianTopology> find(const MatrixX3i& F, int num_vertices) const;
  // Number of topologies held.
  std::size_t size() const;

 private:
  std::unordered_map<std::uint64_t, std::vector<std::shared_ptr<const LaplacianTopology>>> by_hash_;
};

// Precompute-then-query form of deform_element for an element deformed repeatedly with different
// constraint sets. Keeps the topology (above), delta = L V and L^T delta, so that each solve only
// fills values and factorises. Each solve() is const and thread-safe.
class LaplacianDeformer {
 public:
  //   V  #V by 3 rest positions (finite)
  //   F  #F by 3 vertex indices in [0, #V)
  // Throws InvalidInput for a non-finite position, an index out of range, or mu not > 0.
  LaplacianDeformer(const MatrixX3d& V, const MatrixX3i& F, const DeformationOptions& options = {});
  // The same with a precomputed topology of the element's faces (topology->num_vertices() rows
  // in V); bitwise the same solves. Throws InvalidInput for a null topology, a row count that
  // differs, a non-finite position or mu not > 0.
  LaplacianDeformer(std::shared_ptr<const LaplacianTopology> topology, const MatrixX3d& V,
                    const DeformationOptions& options = {});

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
  int num_components() const { return topology_->num_components(); }
  // Connected component of each vertex (through the edges of F), #V.
  const std::vector<int>& vertex_components() const { return topology_->vertex_components(); }
  const Eigen::SparseMatrix<double>& laplacian() const { return topology_->laplacian(); }
  // Laplacian coordinates delta = L V of the rest positions, #V by 3.
  const MatrixX3d& laplacian_coordinates() const { return delta_; }
  const DeformationOptions& options() const { return options_; }

 private:
  void init_values();

  std::shared_ptr<const LaplacianTopology> topology_;
  MatrixX3d V_;
  DeformationOptions options_;
  MatrixX3d delta_;
  Eigen::MatrixXd rhs_;  // P L^T delta, permuted, #V by 3
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
  // >= 0: solved by deform_locally with these rings and margin (the constraints without
  // anchors), for an element too long to solve whole; -1: by deform_element.
  int local_rings = -1;
  int local_margin = 0;
};

// Deforms independent elements in parallel with oneTBB (the per-element loop of section 2.6).
// Result j is exactly deform_element(*jobs[j].V, *jobs[j].F, jobs[j].constraints, options)
// (deform_locally's V for a local job), whatever the thread count; jobs whose faces are in
// `topologies` (optional) reuse them.
// Throws InvalidInput for a null V or F, and otherwise the exception of the lowest-index
// failing job.
std::vector<MatrixX3d> deform_elements(const std::vector<DeformationJob>& jobs,
                                       const DeformationOptions& options = {},
                                       const LaplacianTopologyCache* topologies = nullptr);

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

// A deformation kept local and solved where it acts.
struct LocalDeformation {
  MatrixX3d V;                    // #V by 3 new positions
  std::vector<char> moved_faces;  // #F flags: a vertex of the face was solved for
};

// Eq. (5) with anchor_far_vertices' anchors (`rings`), solved only over the faces whose vertices
// all lie within rings + margin hops of the constrained vertices: the vertices farther out keep
// their positions exactly, where the whole solve would move them by a fraction of the
// deformation that decays ring by ring past the anchors. The cost is then that of the
// neighbourhood of the constraints, not of the element (a long thread stitched at one end).
//   V  #V by 3, F  #F by 3; constraints as for LaplacianDeformer::solve, on V's indices
// Throws InvalidInput for rings or margin < 0 and as LaplacianDeformer::solve.
// An element wholly within reach, or whose topology `topologies` (optional) holds, is solved
// whole, exactly as deform_element with those anchors (with the held topology).
LocalDeformation deform_locally(const MatrixX3d& V, const MatrixX3i& F,
                                const std::vector<LinearConstraint>& constraints, int rings,
                                int margin, const DeformationOptions& options = {},
                                const LaplacianTopologyCache* topologies = nullptr);

}  // namespace mq
