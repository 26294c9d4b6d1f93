// Where the cones of a seamless layout go: moved over the surface so that the flat cone metric
// they define (core/surface/trivial_connection) scales the surface as little as possible, in the
// spirit of Ben-Chen, Gotsman and Bunin (2008) and Myles and Zorin (2013), who place cones where
// the conformal factor is extreme.
//
// Why (issue 23, "even elements"): in a conformal layout an element's size on the surface is
// its size in the plane over e^u. The smooth line field puts its cones where the field is
// smoothest, not where they flatten the surface best; a pole it leaves (index 1: the two poles
// of Blender's UV sphere) cannot be closed by the half-turn lattice at all. Moved to lower the
// area-weighted sum of u^2, the cones spread the curvature so that most of the surface keeps
// the texture's size. Cones are moved, not added: a half-turn cone's own logarithmic peak costs
// more than it saves (measured: no + and - pair among the 36 best candidates lowered the
// distortion away from the cones on Spot or Suzanne), and each is a lattice defect.
#pragma once

#include <vector>

#include "core/surface/trivial_connection.h"

namespace mq {

struct ConePlacementOptions {
  int max_rounds = 40;  // rounds of moves (each: two Poisson solves)
  int reach = 3;        // a cone moves at most this many edges per round
  // A + and a - cone are cancelled when that raises E by at most this much (each cone is a
  // lattice defect: 4-7 rings around it miss a link on Spot). Measured, interior rings with
  // their 4 links at 0 / 0.01 / 0.03: Spot 91.0 / 94.6 / 96.5%, cup 93.9 / 95.5 / 95.5%,
  // bunny 86.3 / 86.3 / 87.3%, knight 71.1 / 72.4 / 71.2%, a torus 97.7 / 100 / 100%; at 0.01
  // no base measured lost links, size or aspect, at 0.03 the bunny's median ring fell from 0.98
  // to 0.93 of the swatch's and its density rose to 109%. Negative: none cancelled.
  double pair_allowance = 0.01;
  // The nearest opposite cones (in edges) each + cone is tried against, and the most solves
  // the cancellation may take (a base of hundreds of cones keeps its cost bounded).
  int pair_candidates = 3;
  int max_pair_solves = 400;
  // #V log scale the metric should have (a size map's, issue 25: the layout's scale is the
  // inverse of the element size); empty: 0, the surface's own size everywhere. E then measures
  // u - target.
  Eigen::VectorXd target;
};

struct ConePlacementReport {
  int split_poles = 0;  // cones of more than one unit split into unit cones first
  int rounds = 0;
  int moves = 0;
  int cancelled = 0;                           // + and - cones that met and cancelled
  int pairs_cancelled = 0;                     // of them, cancelled within pair_allowance
  double energy_before = 0, energy_after = 0;  // sum A u^2 / sum A
};

// Splits every cone of |index| > 1 into unit cones (on the vertex and its nearest interior
// neighbours), then moves cones one interior vertex ring at a time towards lower
// E = sum_v A_v u_v^2 (first order in the sensitivity G (A u), checked by a solve after each
// round: a round that does not lower E is undone and the reach halved), u taken against
// options.target when one is given. A + and a - cone that
// meet cancel; then, one pair at a time, the + and - cones whose cancelling raises E least are
// cancelled while that is at most options.pair_allowance, and the rest moved again. The indices
// keep their sums per component. Deterministic.
//   solver  the factorised trivial connection of the mesh
//   index   #V indices (units of 1/N turn), admissible for solver
// Returns the moved indices. Throws InvalidInput for a size mismatch or bad options.
std::vector<int> place_cones(const TrivialConnection& solver, std::vector<int> index,
                             const Adjacency& vertex_neighbours,
                             const ConePlacementOptions& options = {},
                             ConePlacementReport* report = nullptr);

// u - target (#V each), less its area-weighted mean on each component: the part of a size map's
// scale a cone metric misses.
Eigen::VectorXd misfit(const TrivialConnection& solver, const Eigen::VectorXd& u,
                       const Eigen::VectorXd& target);

// E = sum_v A_v u_v^2 / sum_v A_v: the mean squared log scale of a cone metric (u minus the
// target's log scale, when one is given and non-empty, #V).
double scale_energy(const TrivialConnection& solver, const Eigen::VectorXd& u,
                    const Eigen::VectorXd& target = {});

}  // namespace mq
