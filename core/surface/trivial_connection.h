// A line field (or any N-direction field) with prescribed singularities that is parallel in a
// conformally flat cone metric, and that metric's log scale factor u: the trivial connection of
// Crane, Desbrun and Schroeder (2010), its rotation weighted by the cotangent weights so that,
// away from handles, it is the Levi-Civita connection of the flat metric e^(2u) g.
//
// Why (issue 23, "even elements"): a map whose gradient follows a unit frame field is only
// integrable where the field has no curl; on a curved surface it has, and the least-squares fit
// of core/surface/global_parameterization then spread the misfit as stretch along one direction and
// squeeze along the other (rings on a sphere 1.14x by 0.75x the swatch's). A field parallel in
// the flat metric, scaled by e^u, is integrable: the parameterisation it gives is conformal, so
// elements keep their shape, and only their spacing follows e^u, which the cones' placement
// keeps near 1 (core/surface/cone_placement).
#pragma once

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_topology.h"
#include "core/surface/line_field.h"

namespace mq {

struct ConeMetric {
  // #V log scale factor: Delta u = K - k at interior vertices (cotangent Laplacian, K the angle
  // defect, k = index 2 pi / N the cone's curvature), u = 0 on boundaries; on a closed
  // component, mean zero. The metric e^(2u) g is flat away from the cones.
  Eigen::VectorXd u;
  // #E rotation of the connection against Levi-Civita transport across each interior edge, from
  // its first face to its second (0 on other edges).
  Eigen::VectorXd rotation;
  // Parallel for transport + rotation, each component turned as a whole to agree best with the
  // guidance; its index equals the prescribed one at interior vertices (0 elsewhere).
  DirectionField field;
};

// The factorisations for one mesh, reused for many cone sets (core/surface/cone_placement moves
// cones and solves again): the cotangent Laplacian of the interior vertices, and that Laplacian
// augmented by one row per homology generator (tree-cotree: each handle's two loops, and each
// boundary loop but one per component) whose holonomy is rounded to a multiple of 2 pi / N.
class TrivialConnection {
 public:
  //   V #V by 3, F #F by 3 (consistently oriented), topo = edge_topology(F, #V),
  //   TT = face_adjacency(topo); N in [1, 4].
  // Throws InvalidInput for sizes that do not match or N out of range; SolverFailure when a
  // factorisation fails.
  TrivialConnection(const MatrixX3d& V, const MatrixX3i& F, const EdgeTopology& topo,
                    const MatrixX3i& TT, int N = 2);

  // Whether each vertex carries an index: interior (all its edges manifold) and one fan.
  const std::vector<char>& interior() const { return interior_; }
  // #V angle defects (0 where not interior) and #V vertex areas (a third of the incident faces').
  const Eigen::VectorXd& angle_defect() const { return K_; }
  const Eigen::VectorXd& vertex_area() const { return area_; }
  // #V component of each vertex, and whether each component is closed (no interior-less vertex).
  const std::vector<int>& vertex_component() const { return component_; }
  const std::vector<char>& closed_component() const { return closed_; }
  int N() const { return N_; }  // NOLINT(readability-identifier-naming): the paper's N

  // Indices (#V, units of 1/N turn) are admissible when every closed component's sum is N chi.
  // Returns the first closed component where it is not, or -1.
  int unbalanced_component(const std::vector<int>& index) const;

  // u for the given indices (ConeMetric::u): one back-substitution. boundary (#V, or empty: 0)
  // gives u at the vertices that are not interior (a flat metric leaves them free; issue 25: a
  // size map's log scale, which u held to 0 there could follow only through cones, on an open
  // plane not at all); entries at interior vertices are ignored.
  // Throws InvalidInput for a size mismatch or unbalanced indices.
  Eigen::VectorXd log_scale(const std::vector<int>& index,
                            const Eigen::VectorXd& boundary = Eigen::VectorXd()) const;

  // The Laplacian's inverse applied to a right-hand side per vertex (rows of boundary vertices
  // ignored; result 0 there; mean zero on closed components): for the gradient of a distortion
  // energy with respect to moving cones.
  Eigen::VectorXd solve_poisson(const Eigen::VectorXd& rhs) const;

  // The metric and the field for the given indices; guidance #F by 3 (zero rows ignored);
  // boundary as for log_scale (the rotation is then the metric's with those values).
  // Throws InvalidInput for sizes that do not match or unbalanced indices; SolverFailure.
  ConeMetric solve(const std::vector<int>& index, const MatrixX3d& guidance,
                   const Eigen::VectorXd& boundary = Eigen::VectorXd()) const;

 private:
  // The constructor's steps, in order.
  void mark_interior_vertices();
  void measure_metric();  // K_, area_, weight_, transport_
  void find_components();
  std::vector<Eigen::Triplet<double>> vertex_rows();  // row_of_vertex_, their incidence
  std::vector<char> primal_tree() const;              // #E: in the tree of tree-cotree
  int add_generator_rows(const std::vector<char>& in_tree,
                         std::vector<Eigen::Triplet<double>>& t);  // returns all rows
  void factorise(const std::vector<Eigen::Triplet<double>>& t, int rows);
  // b's generator rows (b's vertex rows set; y = boundary_rotation, zero without boundary
  // values): each generator's holonomy rounded to whole 1/N turns from the flat metric's own.
  void set_generator_rows(Eigen::VectorXd& b, const Eigen::VectorXd& y) const;
  // #E: W A_B^T u_B, the rotation the boundary values alone give (A_B the signed incidence of the
  // vertices that are not interior, built as the vertex rows'). Empty boundary: zero.
  Eigen::VectorXd boundary_rotation(const Eigen::VectorXd& boundary) const;

  MatrixX3d V_;
  MatrixX3i F_;
  EdgeTopology topo_;
  MatrixX3i TT_;
  int N_ = 2;
  std::vector<char> interior_, closed_;
  std::vector<int> component_;
  Eigen::VectorXd K_, area_, weight_, transport_;  // weight_, transport_: #E
  std::vector<int> row_of_vertex_;                 // -1: no row (boundary, or a closed
                                                   // component's dropped vertex)
  int vertex_rows_ = 0;
  Eigen::SparseMatrix<double> A_;           // (vertex rows + generators) by #E, signed incidence
  std::vector<double> generator_holonomy_;  // Levi-Civita holonomy around each generator
  std::vector<std::vector<int>> component_vertices_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> laplacian_, augmented_;
};

// One-off form: TrivialConnection(V, F, topo, TT, N).solve(index, guidance).
ConeMetric trivial_connection(const MatrixX3d& V, const MatrixX3i& F, const EdgeTopology& topo,
                              const MatrixX3i& TT, const std::vector<int>& index,
                              const MatrixX3d& guidance, int N = 2);

}  // namespace mq
