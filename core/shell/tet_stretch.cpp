#include "core/shell/tet_stretch.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "core/common/errors.h"

namespace mq {

namespace {

// Eq. (8) for one tet, closed form; mirrored operation for operation in kernels/tet_stretch.cl.
// J = S Tt^-1 = S adj(Tt) / det(Tt), with S and Tt holding the edges from corner 0 as columns.
// adj(Tt) rows are the cross products of Tt's columns, so column k of J is
// (sum_m S_m (r_m)_k) / det: a, b, c follow without forming the inverse.
inline double stretch_closed_form(const double* s0, const double* s1, const double* s2,
                                  const double* s3, const double* t0, const double* t1,
                                  const double* t2, const double* t3) {
  double e[3][3], q[3][3];  // e[m]: shell edge m, q[m]: texture edge m
  for (int a = 0; a < 3; ++a) {
    e[0][a] = s1[a] - s0[a];
    e[1][a] = s2[a] - s0[a];
    e[2][a] = s3[a] - s0[a];
    q[0][a] = t1[a] - t0[a];
    q[1][a] = t2[a] - t0[a];
    q[2][a] = t3[a] - t0[a];
  }
  // Rows of adj(Tt): r0 = q1 x q2, r1 = q2 x q0, r2 = q0 x q1; det(Tt) = q0 . r0.
  double r[3][3];
  const int i1[3] = {1, 2, 0}, i2[3] = {2, 0, 1};
  for (int m = 0; m < 3; ++m) {
    const double* u = q[i1[m]];
    const double* v = q[i2[m]];
    r[m][0] = u[1] * v[2] - u[2] * v[1];
    r[m][1] = u[2] * v[0] - u[0] * v[2];
    r[m][2] = u[0] * v[1] - u[1] * v[0];
  }
  const double det_t = q[0][0] * r[0][0] + q[0][1] * r[0][1] + q[0][2] * r[0][2];
  const double det_s = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) +
                       e[0][1] * (e[1][2] * e[2][0] - e[1][0] * e[2][2]) +
                       e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
  if (!(det_t * det_s > 0.0)) return kInf;
  // Column k of S adj(Tt) is sum_m e[m] * r[m][k].
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    for (int a = 0; a < 3; ++a) {
      const double c = e[0][a] * r[0][k] + e[1][a] * r[1][k] + e[2][a] * r[2][k];
      sum += c * c;
    }
  }
  return std::sqrt(sum / (det_t * det_t) / 3.0);
}

}  // namespace

double tet_stretch(const Vector3d* s, const Vector3d* t) {
  return stretch_closed_form(s[0].data(), s[1].data(), s[2].data(), s[3].data(), t[0].data(),
                             t[1].data(), t[2].data(), t[3].data());
}

void validate_stretch_problem(const StretchProblem& problem) {
  MQ_CHECK(problem.shell_V.rows() == problem.texture_V.rows(), InvalidInput,
           "tet stretch: ", problem.shell_V.rows(), " shell vertices but ",
           problem.texture_V.rows(), " texture vertices");
  MQ_CHECK(problem.shell_V.allFinite(), InvalidInput,
           "tet stretch: shell vertices contain NaN or infinite values");
  MQ_CHECK(problem.texture_V.allFinite(), InvalidInput,
           "tet stretch: texture vertices contain NaN or infinite values");
  MQ_CHECK(problem.T.rows() == 0 ||
               (problem.T.minCoeff() >= 0 && problem.T.maxCoeff() < problem.shell_V.rows()),
           InvalidInput, "tet stretch: tet index out of range [0, ", problem.shell_V.rows(), ")");
}

Eigen::VectorXd TetStretchCpu::per_tet(const StretchProblem& pb) {
  validate_stretch_problem(pb);
  Eigen::VectorXd out(pb.T.rows());
  const Eigen::Index nt = pb.T.rows();
  tbb::parallel_for(
      tbb::blocked_range<Eigen::Index>(0, nt), [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index t = r.begin(); t != r.end(); ++t) {
          const int* v = pb.T.row(t).data();
          const double* S = pb.shell_V.data();
          const double* X = pb.texture_V.data();
          out(t) = stretch_closed_form(S + 3 * v[0], S + 3 * v[1], S + 3 * v[2], S + 3 * v[3],
                                       X + 3 * v[0], X + 3 * v[1], X + 3 * v[2], X + 3 * v[3]);
        }
      });
  return out;
}

Eigen::VectorXd tet_stretch_reference(const StretchProblem& pb) {
  validate_stretch_problem(pb);
  Eigen::VectorXd out(pb.T.rows());
  for (Eigen::Index t = 0; t < pb.T.rows(); ++t) {
    Eigen::Matrix3d S, Tt;
    for (int m = 0; m < 3; ++m) {
      S.col(m) = (pb.shell_V.row(pb.T(t, m + 1)) - pb.shell_V.row(pb.T(t, 0))).transpose();
      Tt.col(m) = (pb.texture_V.row(pb.T(t, m + 1)) - pb.texture_V.row(pb.T(t, 0))).transpose();
    }
    if (!(S.determinant() * Tt.determinant() > 0.0)) {
      out(t) = kInf;
      continue;
    }
    const Eigen::Matrix3d J = S * Tt.inverse();  // d(shell) / d(texture)
    out(t) = std::sqrt(J.colwise().squaredNorm().sum() / 3.0);
  }
  return out;
}

double total_stretch(const StretchProblem& pb, const Eigen::VectorXd& per_tet) {
  validate_stretch_problem(pb);
  MQ_CHECK(per_tet.size() == pb.T.rows(), InvalidInput, "total stretch: ", per_tet.size(),
           " per-tet values for ", pb.T.rows(), " tets");
  MQ_CHECK(pb.T.rows() > 0, InvalidInput, "total stretch: no tets");
  MQ_CHECK(!per_tet.hasNaN() && (per_tet.array() >= 0.0).all(), InvalidInput,
           "total stretch: per-tet values must be >= 0 and not NaN");
  if ((per_tet.array() == kInf).any()) return kInf;
  double vs = 0.0, vt = 0.0, weighted = 0.0;
  for (Eigen::Index t = 0; t < pb.T.rows(); ++t) {
    const int* v = pb.T.row(t).data();
    const double s = std::abs(tet_volume(pb.shell_V.row(v[0]), pb.shell_V.row(v[1]),
                                         pb.shell_V.row(v[2]), pb.shell_V.row(v[3])));
    const double x = std::abs(tet_volume(pb.texture_V.row(v[0]), pb.texture_V.row(v[1]),
                                         pb.texture_V.row(v[2]), pb.texture_V.row(v[3])));
    vs += s;
    vt += x;
    weighted += per_tet(t) * per_tet(t) * s;  // Eq. (9): weights are shell volumes
  }
  MQ_CHECK(vs > 0.0 && vt > 0.0, InvalidInput, "total stretch: zero total shell or texture volume");
  return std::sqrt(weighted / vs) * std::cbrt(vt / vs);
}

}  // namespace mq
