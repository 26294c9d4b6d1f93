// Stretch of the shell map, paper section 3.2, Eqs. (8)-(9).
//
// Convention. The paper writes J for the Jacobian of g: shell -> texture and normalises the
// total by sqrt(sum |T_t| / sum |T_s|), a 2D carry-over from Sander et al. 2001 for which 1.0
// is not a lower bound in 3D (two equal shell tets scaled by 1 and 0.001 give 0.79). We follow
// Sander's convention instead, which does give the bound: J = d(shell) / d(texture), the
// Jacobian of g^-1 (Sander's parameterisation maps texture to surface), so
//   L2(T)   = sqrt((a + b + c) / 3),  a, b, c the squared column norms of J          (8)
//   L2(M)   = sqrt(sum_i L2(T_i)^2 |T_s,i| / sum_i |T_s,i|)                           (9)
//   L2n(M)  = L2(M) * (sum |T_t| / sum |T_s|)^(1/3)
// Proof that L2n >= 1: with d_i = det J_i = |T_s,i| / |T_t,i| and singular values s_k of J_i,
// AM-GM gives L2(T_i)^2 = (s1^2 + s2^2 + s3^2) / 3 >= d_i^(2/3), so
//   L2(M)^2 >= sum_i d_i^(5/3) |T_t,i| / V_s >= V_t (V_s / V_t)^(5/3) / V_s = (V_s / V_t)^(2/3)
// by Jensen (x^(5/3) convex, weights |T_t,i| / V_t, sum of d_i |T_t,i| = V_s). Equality holds
// iff every J_i is the same scalar times a rotation: a global similarity. Hence the cube root
// (volumes scale with the cube of lengths) where the paper's 2D formula has a square root.
// A uniform scale texture = s * shell gives L2(T) = 1/s per tet and L2n = 1.
#pragma once

#include <Eigen/Core>
#include <string>

#include "core/mesh/mesh.h"
#include "core/shell/tet_mesh.h"

namespace mq {

// One stretch evaluation. The shell side is usually fixed while texture_V moves (the
// optimisation moves the (u, v) of offset vertices).
//   shell_V    #V by 3 shell-space positions (finite)
//   texture_V  #V by 3 texture-space positions (u, v, w) (finite)
//   T          #T by 4 tets indexing both
struct StretchProblem {
  MatrixX3d shell_V;
  MatrixX3d texture_V;
  TetIndices T;
};

// Throws InvalidInput when shell_V and texture_V differ in row count, contain NaN/inf, or a
// tet index lies outside [0, #V).
void validate_stretch_problem(const StretchProblem& problem);

// Per-tet L2 stretch (Eq. 8) of the map, +infinity where the texture tet is degenerate or
// its orientation differs from the shell tet's (the map folds there: a line search then rejects
// the move, as in Sander et al.), and for degenerate shell tets.
class TetStretchEvaluator {
 public:
  virtual ~TetStretchEvaluator() = default;
  // Returns #T values (see above). Throws InvalidInput (validate_stretch_problem); DeviceError
  // for device failures.
  virtual Eigen::VectorXd per_tet(const StretchProblem& problem) = 0;
  virtual std::string name() const = 0;
};

// CPU path: TBB over tets, each writing its own slot (closed-form adjugate inverse).
class TetStretchCpu final : public TetStretchEvaluator {
 public:
  Eigen::VectorXd per_tet(const StretchProblem& problem) override;
  std::string name() const override { return "cpu"; }
};

// Eq. (8) for one tet from its shell corners s[0..3] and texture corners t[0..3], with the same
// closed form as TetStretchCpu (+infinity when the texture tet is degenerate or its orientation
// differs from the shell tet's). For local evaluations in an optimiser.
double tet_stretch(const Vector3d* s, const Vector3d* t);

// Reference: a plain loop with Eigen's 3x3 inverse, J = S * Tt^-1 with S, Tt the edge matrices.
// Throws InvalidInput like the evaluators.
Eigen::VectorXd tet_stretch_reference(const StretchProblem& problem);

// Eq. (9) normalised (see the header comment): >= 1, equal to 1 iff the map is a similarity;
// +infinity when a per-tet value is infinite. Sums run in tet order (deterministic).
//   per_tet  #T values from an evaluator
// Throws InvalidInput (validate_stretch_problem, per_tet of the wrong size, a NaN or negative
// value, no tets, or zero total shell or texture volume).
double total_stretch(const StretchProblem& problem, const Eigen::VectorXd& per_tet);

}  // namespace mq
