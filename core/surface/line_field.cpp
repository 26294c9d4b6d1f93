#include "core/surface/line_field.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>

#include "core/common/errors.h"

namespace mq {

namespace {

// Angle of the edge e's vector (E(e,0) -> E(e,1)) in face f's frame.
double edge_angle(const MatrixX3d& V, const EdgeTopology& topo, const FaceFrames& fr, int e,
                  int f) {
  const Vector3d d = (V.row(topo.E(e, 1)) - V.row(topo.E(e, 0))).transpose();
  return std::atan2(d.dot(fr.b2.row(f).transpose()), d.dot(fr.b1.row(f).transpose()));
}

double transport(const MatrixX3d& V, const EdgeTopology& topo, const FaceFrames& fr, int e) {
  const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
  return edge_angle(V, topo, fr, e, g) - edge_angle(V, topo, fr, e, f);
}

bool interior(const EdgeTopology& topo, int e) { return topo.edge_faces.degree(e) == 2; }

double angle_of(const Vector3d& d, const FaceFrames& fr, int f) {
  return std::atan2(d.dot(fr.b2.row(f).transpose()), d.dot(fr.b1.row(f).transpose()));
}

Vector3d direction_at(double theta, const FaceFrames& fr, int f) {
  return (std::cos(theta) * fr.b1.row(f) + std::sin(theta) * fr.b2.row(f)).transpose();
}

}  // namespace

double transport_angle(const MatrixX3d& V, const EdgeTopology& topo, const FaceFrames& frames,
                       int e) {
  return transport(V, topo, frames, e);
}

double angle_in_frame(const Vector3d& d, const FaceFrames& frames, int f) {
  return angle_of(d, frames, f);
}

Vector3d direction_in_frame(double theta, const FaceFrames& frames, int f) {
  return direction_at(theta, frames, f);
}

FaceFrames face_frames(const MatrixX3d& V, const MatrixX3i& F) {
  FaceFrames fr;
  const Eigen::Index nf = F.rows();
  fr.b1.resize(nf, 3);
  fr.b2.resize(nf, 3);
  fr.n.resize(nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f) {
    const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    Vector3d n = (b - a).cross(c - a);
    Vector3d e = b - a;
    if (!(n.norm() > 0)) n = Vector3d::UnitZ();
    n.normalize();
    e -= e.dot(n) * n;
    if (!(e.norm() > 0)) e = n.unitOrthogonal();
    e.normalize();
    fr.n.row(f) = n.transpose();
    fr.b1.row(f) = e.transpose();
    fr.b2.row(f) = n.cross(e).transpose();
  }
  return fr;
}

DirectionField direction_field_matching(const MatrixX3d& V, const MatrixX3i& F,
                                        const EdgeTopology& topo, const MatrixX3d& direction,
                                        int N) {
  MQ_CHECK(N >= 1 && N <= 4, InvalidInput, "direction field: N must be in [1, 4], got ", N);
  MQ_CHECK(direction.rows() == F.rows(), InvalidInput, "direction field: ", direction.rows(),
           " directions for ", F.rows(), " faces");
  const FaceFrames fr = face_frames(V, F);
  DirectionField out;
  out.N = N;
  out.direction = direction;
  const int ne = topo.num_edges();
  out.matching.assign(static_cast<size_t>(ne), 0);
  std::vector<double> smooth(static_cast<size_t>(ne), 0.0);  // rotation of g's rep against f's
  const double unit = kTwoPi / N;
  for (int e = 0; e < ne; ++e) {
    if (!interior(topo, e)) continue;
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    const double raw = angle_of(direction.row(g).transpose(), fr, g) -
                       (angle_of(direction.row(f).transpose(), fr, f) + transport(V, topo, fr, e));
    const long k = std::lround(raw / unit);
    out.matching[e] = static_cast<int>(((k % N) + N) % N);
    smooth[e] = raw - k * unit;
  }
  // Index: around each interior vertex, the field's rotation against parallel transport plus
  // the angle defect, in turns (a smooth field around a flat vertex: 0).
  const int nv = static_cast<int>(V.rows());
  out.index.assign(static_cast<size_t>(nv), 0);
  std::vector<double> angle_sum(static_cast<size_t>(nv), 0.0);
  std::vector<char> boundary(static_cast<size_t>(nv), 0);
  for (int e = 0; e < ne; ++e)
    if (!interior(topo, e)) boundary[topo.E(e, 0)] = boundary[topo.E(e, 1)] = 1;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Vector3d a = V.row(F(f, c)), b = V.row(F(f, (c + 1) % 3)), d = V.row(F(f, (c + 2) % 3));
      const Vector3d u = b - a, w = d - a;
      if (u.norm() > 0 && w.norm() > 0)
        angle_sum[F(f, c)] += std::atan2(u.cross(w).norm(), u.dot(w));
    }
  // Rotation sums: each interior edge (v, w) contributes to both endpoints, signed by the
  // direction of travel around the endpoint (counter-clockwise seen from outside).
  std::vector<double> rotation(static_cast<size_t>(nv), 0.0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      // Around vertex a = F(f, c), counter-clockwise, the next face is across edge (d, a).
      const int k = (c + 2) % 3;
      const int e = topo.FE(f, k);
      if (!interior(topo, e)) continue;
      const int first = topo.edge_faces.begin(e)[0];
      rotation[F(f, c)] += (first == f) ? smooth[e] : -smooth[e];
    }
  for (int v = 0; v < nv; ++v) {
    if (boundary[v]) continue;
    const double turns = (rotation[v] + (kTwoPi - angle_sum[v])) / kTwoPi;
    out.index[v] = static_cast<int>(std::lround(turns * N));
  }
  return out;
}

namespace {

// The smoothness energy of an N-direction field, sum over interior edges of w |z_g - R z_f|^2,
// as a real 2 #F system in z = (x, y) per face: off-diagonal triplets, and the diagonal (the
// smoothness degree; the guidance adds to diag, not to degree).
struct SmoothnessSystem {
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd diag, degree, rhs;  // 2 #F each
};

SmoothnessSystem smoothness_system(const MatrixX3d& V, const EdgeTopology& topo,
                                   const FaceFrames& fr, const std::vector<double>& area, int N) {
  const int nf = static_cast<int>(area.size());
  SmoothnessSystem sys;
  sys.rhs = Eigen::VectorXd::Zero(2 * nf);
  sys.diag = Eigen::VectorXd::Zero(2 * nf);
  sys.degree = Eigen::VectorXd::Zero(2 * nf);
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (!interior(topo, e)) continue;
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    const double r = N * transport(V, topo, fr, e), c = std::cos(r), s = std::sin(r);
    // w |z_g - R z_f|^2: blocks (f,f) w I, (g,g) w I, (g,f) -w R, (f,g) -w R^T. The weight
    // |e|^2 / (A_f + A_g) (about the ratio of the dual edge to the edge) makes the energy a
    // discretisation of the field's Dirichlet energy, independent of the triangulation: with
    // unit weights the slivers a bisected base has gathered singularities.
    const double len2 = (V.row(topo.E(e, 1)) - V.row(topo.E(e, 0))).squaredNorm();
    const double w = area[f] + area[g] > 0 ? len2 / (area[f] + area[g]) : 1.0;
    sys.diag(2 * f) += w, sys.diag(2 * f + 1) += w, sys.diag(2 * g) += w, sys.diag(2 * g + 1) += w;
    sys.degree(2 * f) += w, sys.degree(2 * f + 1) += w;
    sys.degree(2 * g) += w, sys.degree(2 * g + 1) += w;
    const double R[2][2] = {{c, -s}, {s, c}};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        sys.t.emplace_back(2 * g + i, 2 * f + j, -w * R[i][j]);
        sys.t.emplace_back(2 * f + j, 2 * g + i, -w * R[i][j]);
      }
  }
  return sys;
}

// The guidance's pull: w |z_f - e^(i N theta_f)|^2 per face with guidance, w its weight times
// the face's share of the mean area.
void add_guidance(SmoothnessSystem& sys, const MatrixX3d& guidance, const FaceFrames& fr,
                  const std::vector<double>& area, double mean_area, int N, double weight) {
  for (int f = 0; f < static_cast<int>(area.size()); ++f) {
    const Vector3d q = guidance.row(f).transpose();
    const double len = std::hypot(q.dot(fr.b1.row(f).transpose()), q.dot(fr.b2.row(f).transpose()));
    // The guidance's weight scales with its length's presence only (unit weight where defined).
    const double w = weight * area[f] / mean_area * (len > 0 ? 1.0 : 0.0);
    const double theta = len > 0 ? angle_of(q, fr, f) : 0.0;
    sys.diag(2 * f) += w + 1e-9, sys.diag(2 * f + 1) += w + 1e-9;
    sys.rhs(2 * f) += w * std::cos(N * theta);
    sys.rhs(2 * f + 1) += w * std::sin(N * theta);
  }
}

// The field that minimises smoothness plus guidance.
Eigen::VectorXd fitted_field(SmoothnessSystem& sys) {
  const Eigen::Index n = sys.rhs.size();
  for (int i = 0; i < n; ++i) sys.t.emplace_back(i, i, sys.diag(i));
  Eigen::SparseMatrix<double> M(n, n);
  M.setFromTriplets(sys.t.begin(), sys.t.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
  MQ_CHECK(ldlt.info() == Eigen::Success, SolverFailure,
           "direction field: the smoothness system could not be factorised");
  Eigen::VectorXd z = ldlt.solve(sys.rhs);
  MQ_CHECK(ldlt.info() == Eigen::Success && z.allFinite(), SolverFailure,
           "direction field: the smoothness solve failed");
  return z;
}

// The smoothest field (Knoeppel et al. 2013): the smallest eigenvector of the smoothness energy
// against the area, by inverse iteration from the guidance, then turned as a whole to agree best
// with the guidance. Its singularities are the fewest and mildest the surface allows (on a
// sphere, four half-turn cones, where a weighted fit to a guidance with two poles can keep the
// poles).
Eigen::VectorXd smoothest_field(const SmoothnessSystem& sys, const std::vector<double>& area,
                                double mean_area) {
  const int nf = static_cast<int>(area.size());
  Eigen::VectorXd mass(2 * nf);
  for (int f = 0; f < nf; ++f) mass(2 * f) = mass(2 * f + 1) = area[f] / mean_area;
  const double shift = 1e-8 * std::max(1.0, sys.degree.sum() / (2 * nf));
  std::vector<Eigen::Triplet<double>> ts;
  ts.reserve(sys.t.size() + 2 * nf);
  for (const auto& e : sys.t) ts.push_back(e);
  // diag holds the smoothness degree plus the guidance weight; the weight is not part of the
  // energy whose eigenvector is sought.
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 2; ++c)
      ts.emplace_back(2 * f + c, 2 * f + c, sys.degree(2 * f + c) + shift * mass(2 * f + c));
  Eigen::SparseMatrix<double> M(2 * nf, 2 * nf);
  M.setFromTriplets(ts.begin(), ts.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
  MQ_CHECK(ldlt.info() == Eigen::Success, SolverFailure,
           "direction field: the smoothness system could not be factorised");
  Eigen::VectorXd z = sys.rhs;
  if (!(z.norm() > 0)) z.setOnes();
  for (int it = 0; it < 30; ++it) {
    z = ldlt.solve(mass.cwiseProduct(z)).eval();
    MQ_CHECK(ldlt.info() == Eigen::Success && z.allFinite(), SolverFailure,
             "direction field: the smoothness solve failed");
    z /= std::sqrt(z.dot(mass.cwiseProduct(z)));
  }
  // Global phase: maximise Re sum A conj(zhat) z over a common turn of every z.
  double re = 0, im = 0;
  for (int f = 0; f < nf; ++f) {
    const double gx = sys.rhs(2 * f), gy = sys.rhs(2 * f + 1), x = z(2 * f), y = z(2 * f + 1);
    re += gx * x + gy * y;
    im += gx * y - gy * x;
  }
  const double phase = -std::atan2(im, re), c = std::cos(phase), sn = std::sin(phase);
  for (int f = 0; f < nf; ++f) {
    const double x = z(2 * f), y = z(2 * f + 1);
    z(2 * f) = c * x - sn * y;
    z(2 * f + 1) = sn * x + c * y;
  }
  return z;
}

}  // namespace

DirectionField smooth_direction_field(const MatrixX3d& V, const MatrixX3i& F,
                                      const EdgeTopology& topo, const MatrixX3i& TT,
                                      const MatrixX3d& guidance, const LineFieldOptions& options) {
  const int N = options.N;
  MQ_CHECK(N >= 1 && N <= 4, InvalidInput, "direction field: N must be in [1, 4], got ", N);
  MQ_CHECK(guidance.rows() == F.rows(), InvalidInput, "direction field: ", guidance.rows(),
           " guidance vectors for ", F.rows(), " faces");
  MQ_CHECK(std::isfinite(options.guidance_weight) && options.guidance_weight > 0, InvalidInput,
           "direction field: the guidance weight must be positive, got ", options.guidance_weight);
  const FaceFrames fr = face_frames(V, F);
  const int nf = static_cast<int>(F.rows());
  std::vector<double> area(static_cast<size_t>(nf));
  double mean_area = 0;
  for (int f = 0; f < nf; ++f) {
    const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    area[f] = 0.5 * (b - a).cross(c - a).norm();
    mean_area += area[f];
  }
  mean_area = nf > 0 ? mean_area / nf : 1;
  if (!(mean_area > 0)) mean_area = 1;
  SmoothnessSystem sys = smoothness_system(V, topo, fr, area, N);
  add_guidance(sys, guidance, fr, area, mean_area, N, options.guidance_weight);
  const Eigen::VectorXd z =
      options.smoothest ? smoothest_field(sys, area, mean_area) : fitted_field(sys);
  std::vector<double> theta(static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    if (std::hypot(z(2 * f), z(2 * f + 1)) > 1e-12) {
      theta[f] = std::atan2(z(2 * f + 1), z(2 * f)) / N;
    } else {
      const Vector3d q = guidance.row(f).transpose();
      theta[f] = angle_of(q, fr, f);
    }
  }
  // Representatives along a breadth-first dual spanning tree: each face takes the one of its N
  // directions nearest to its parent's transported across the tree edge.
  const double unit = kTwoPi / N;
  breadth_first_dual_tree(TT, [&](int f, int k, int g) {
    const int e = topo.FE(f, k);
    const double rho =
        topo.edge_faces.begin(e)[0] == f ? transport(V, topo, fr, e) : -transport(V, topo, fr, e);
    const double target = theta[f] + rho;
    theta[g] += std::round((target - theta[g]) / unit) * unit;
  });
  MatrixX3d direction(nf, 3);
  for (int f = 0; f < nf; ++f) direction.row(f) = direction_at(theta[f], fr, f).transpose();
  return direction_field_matching(V, F, topo, direction, N);
}

int cancel_singular_pairs(const MatrixX3d& V, const MatrixX3i& F, const EdgeTopology& topo,
                          DirectionField& field) {
  const int N = field.N;
  const int ne = topo.num_edges();
  if (N < 2) return 0;
  const FaceFrames fr = face_frames(V, F);
  const double unit = kTwoPi / N;
  // The sign with which the smooth rotation across e enters the rotation sum around each of
  // its ends (direction_field_matching: each end's fan counts it once, the two ends opposite).
  std::vector<int> sign_at_first(static_cast<size_t>(ne), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int e = topo.FE(f, (c + 2) % 3);
      if (!interior(topo, e)) continue;
      if (F(f, c) != topo.E(e, 0)) continue;
      sign_at_first[e] = topo.edge_faces.begin(e)[0] == f ? 1 : -1;
    }
  int cancelled = 0;
  for (int e = 0; e < ne; ++e) {
    if (!interior(topo, e) || sign_at_first[e] == 0) continue;
    const int a = topo.E(e, 0), b = topo.E(e, 1);
    const int ia = field.index[a], ib = field.index[b];
    if (ia == 0 || ia != -ib) continue;
    // Rotation across e changed by -ia units at a (and +ia at b): both indices become 0.
    const long shift = -static_cast<long>(ia) * sign_at_first[e];
    const int f = topo.edge_faces.begin(e)[0], g = topo.edge_faces.begin(e)[1];
    const double raw =
        angle_of(field.direction.row(g).transpose(), fr, g) -
        (angle_of(field.direction.row(f).transpose(), fr, f) + transport(V, topo, fr, e));
    const long k = std::lround(raw / unit) - shift;
    field.matching[e] = static_cast<int>(((k % N) + N) % N);
    field.index[a] = field.index[b] = 0;
    ++cancelled;
  }
  return cancelled;
}

}  // namespace mq
