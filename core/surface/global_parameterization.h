// A field-aligned global parameterisation of a base mesh: 2D coordinates per face corner whose
// gradient follows a line field (u along the field, v across it, unit scale), continuous inside
// charts and related across cut edges by rigid transitions (a translation, or a half turn plus
// a translation where the line field's matching is a half turn).
//
// Why (beyond the paper's section 3.1): every local patch flattened by its own conformal map
// sees the texture placed by earlier patches through a slightly different map (scale and turn
// drift with the curvature, a few percent over a patch), and a lattice texture such as chain
// mail breaks wherever the misfit exceeds its clearance. Patches flattened through one global
// parameterisation all see the same map: the texture they place continues exactly, as on a
// plane, except around the few singular vertices of the field and where the growth of the quilt
// closes around them or around a handle. The cut graph (a dual spanning tree's complement,
// pruned to the paths that end at singular vertices, boundaries or close handles) is where the
// charts meet; the transitions across it are rigid, so a patch that straddles it is unfolded
// exactly by applying them (PatchUnfolding).
#pragma once

#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_topology.h"
#include "core/surface/line_field.h"

namespace mq {

struct GlobalParameterization {
  MatrixX2d wedge_uv;          // #wedges by 2: the coordinates of each corner group
  MatrixX3i corner_wedge;      // #F by 3: the wedge of each face corner
  std::vector<char> cut;       // #E: edge on the cut graph (charts meet there)
  std::vector<int> sign;       // #E: +1, or -1 where the transition across the edge is a half turn
  std::vector<char> singular;  // #V: the field has a non-zero index at the vertex
  int num_singular = 0;
  int num_cut_edges = 0;
  DirectionField field;
  // Coordinates of face f's corner k.
  Vector2d uv(int f, int k) const { return wedge_uv.row(corner_wedge(f, k)).transpose(); }
};

struct GlobalParameterizationOptions {
  // Weight of the cut constraints against the Dirichlet energy (per unit edge); large makes the
  // transitions exactly rigid.
  double cut_weight = 1e4;
  double pin_weight = 1e4;  // of the pinned vertices
  // The length of the gradients sought (plane units per surface unit), times face_scale(f) on
  // face f when given (#F; empty: 1): e^u of a flat cone metric (core/surface/trivial_connection)
  // makes the sought gradients integrable, and the map conformal.
  double target_scale = 1;
  Eigen::VectorXd face_scale;
  // Vertices whose coordinates (of their first corner group) are fixed, with the same weight:
  // the half-turn cones placed where the texture's own half-turn centres are.
  std::vector<std::pair<int, Vector2d>> pinned;
  // Cut edges whose transition translation is fixed: uv_g = s uv_f + t at both ends.
  std::vector<std::pair<int, Vector2d>> fixed_translation;

  // Throws InvalidInput unless both weights are positive and finite.
  void validate() const;
};

// A maximal chain of cut edges through regular vertices (cut degree 2, not singular, not on a
// boundary): one transition holds along it.
struct CutPath {
  std::vector<int> edges;
  // Per edge: its faces (edge_faces[0], [1]) lie on the path's sides the other way round from
  // the first edge's, so its transition is the inverse of the path's.
  std::vector<char> flipped;
  int sign = 1;
};
std::vector<CutPath> cut_paths(const GlobalParameterization& gp, const EdgeTopology& topo,
                               const MatrixX3i& F);

// The path's transition translation t (uv_g = s uv_f + t, f and g the faces of its first
// edge), averaged over its edges' ends.
Vector2d path_translation(const GlobalParameterization& gp, const EdgeTopology& topo,
                          const MatrixX3i& F, const CutPath& path);
// The translation of edge k of the path (in its own face order) for the path's translation t.
Vector2d edge_translation(const CutPath& path, size_t k, const Vector2d& t);

// Solves min sum_f A_f |grad u - s_f d_f|^2 + |grad v - s_f n_f x d_f|^2 (s_f the target scale
// times face_scale) over corner-group values, with
// the corners around a vertex grouped between cut edges and, for every cut edge (a, b) between
// faces f and g, the constraint uv_g(a) - uv_g(b) = s (uv_f(a) - uv_f(b)) (s the half-turn
// sign), which makes the transition across each cut path one rigid motion.
//   field  a direction field of N = 1 or 2 (smooth_direction_field)
// One sparse factorisation, two right-hand sides. Throws InvalidInput for sizes that do not
// match, a pinned vertex out of range or options.validate() failing, SolverFailure when the
// factorisation or the solve fails.
GlobalParameterization global_parameterization(const MatrixX3d& V, const MatrixX3i& F,
                                               const EdgeTopology& topo, const MatrixX3i& TT,
                                               const DirectionField& field,
                                               const GlobalParameterizationOptions& options = {});

// The parameterisation unfolded over a set of faces (a local patch: a topological disk): the
// coordinates of each patch vertex in the chart of the first face, the others brought there by
// the transitions across the cut edges between them, breadth first.
//   faces       base faces, the first one the root; every face must be reachable from the root
//               through edges shared inside the set
//   vertex_of   for each face in `faces`, its three patch-local vertex indices (#faces by 3)
//   num_local   number of patch-local vertices
// Returns #num_local by 2, or nothing when the unfolding is not consistent (a singular vertex
// inside the set: the faces around it disagree by more than tolerance times their edge length).
bool unfold_patch(const GlobalParameterization& gp, const EdgeTopology& topo, const MatrixX3i& TT,
                  const MatrixX3d& V, const MatrixX3i& F, const std::vector<int>& faces,
                  const MatrixX3i& vertex_of, int num_local, MatrixX2d& uv,
                  double tolerance = 0.05);

// Where a point of the parameter plane lies on the surface: starting in face `face` with x in
// that face's chart, walks across edges towards x (through the transitions across cut edges)
// until a face contains it. face and x are updated to the face found and x in its chart;
// barycentric receives the point's weights on that face's corners. Returns false when the walk
// leaves the surface (a boundary edge) or does not settle within max_steps (around a singular
// vertex, where the charts do not close up).
// transform (optional): composed with the transitions crossed, x_new = sigma x_old + tau
// (start it at sigma = 1, tau = 0 to learn the map from the first chart to the last).
struct ChartTransform {
  double sigma = 1;
  Vector2d tau = Vector2d::Zero();
  Vector2d operator()(const Vector2d& x) const { return sigma * x + tau; }
};
bool locate_in_charts(const GlobalParameterization& gp, const EdgeTopology& topo,
                      const MatrixX3i& TT, const MatrixX3i& F, int& face, Vector2d& x,
                      Vector3d& barycentric, int max_steps = 64,
                      ChartTransform* transform = nullptr);

}  // namespace mq
