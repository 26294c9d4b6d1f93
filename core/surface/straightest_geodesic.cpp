#include "core/surface/straightest_geodesic.h"

#include <algorithm>
#include <cmath>

namespace mq {

namespace {

// Moves `bary` along the unit direction t in the face of corners x (unit normal n, twice the
// area two_a) for `distance`, or to where it leaves the face first (then `distance` is cut to
// the way gone). Returns the corner opposite the edge it leaves by, -1 when it stays inside.
int advance_in_face(const Vector3d (&x)[3], const Vector3d& n, double two_a, const Vector3d& t,
                    Vector3d& bary, double& distance) {
  // Barycentric coordinate k changes along t at the rate grad(b_k) . t.
  double rate[3];
  for (int k = 0; k < 3; ++k) rate[k] = n.cross(x[(k + 2) % 3] - x[(k + 1) % 3]).dot(t) / two_a;
  int exit = -1;
  for (int k = 0; k < 3; ++k)
    if (rate[k] < 0) {
      const double s = std::max(0.0, bary(k)) / -rate[k];
      if (s < distance) {
        distance = s;
        exit = k;
      }
    }
  for (int k = 0; k < 3; ++k) bary(k) += distance * rate[k];
  return exit;
}

template <typename Position>
bool walk(const Position& position, const MatrixX3i& F, const MatrixX3i& TT, int& face,
          Vector3d& bary, const Vector3d& t_in, int max_faces) {
  Vector3d x[3];
  auto load = [&](int f, Vector3d& n) {
    for (int k = 0; k < 3; ++k) x[k] = position(F(f, k));
    n = (x[1] - x[0]).cross(x[2] - x[0]);
    const double twice_area = n.norm();
    if (!(twice_area > 0)) return 0.0;
    n /= twice_area;
    return twice_area;
  };
  Vector3d n;
  double two_a = load(face, n);
  if (two_a == 0) return false;
  Vector3d t = t_in - t_in.dot(n) * n;
  double remaining = t.norm();
  if (!(remaining > 0)) return true;
  t /= remaining;
  for (int step = 0; step < max_faces; ++step) {
    double s_exit = remaining;
    const int exit = advance_in_face(x, n, two_a, t, bary, s_exit);
    if (exit < 0) {
      bary = bary.cwiseMax(0.0);
      bary /= bary.sum();
      return true;
    }
    remaining -= s_exit;
    // The edge opposite corner `exit` runs from corner exit+1 to exit+2: TT's slot exit+1.
    const int a = (exit + 1) % 3, b = (exit + 2) % 3;
    const int g = TT(face, a);
    bary(exit) = 0;
    bary = bary.cwiseMax(0.0);
    bary /= bary.sum();
    if (g < 0) return false;
    // Where on the edge, from its vertex F(face, a) to F(face, b).
    const double lambda = bary(b);
    const int va = F(face, a), vb = F(face, b);
    const Vector3d e = (x[b] - x[a]).normalized();
    // The direction's parts along the edge and across it, out of this face...
    const Vector3d q = x[exit] - x[a];
    const Vector3d out = -(q - q.dot(e) * e).normalized();
    const double along = t.dot(e), across = t.dot(out);
    // ... and into the next, the same angle to the edge.
    Vector3d ng;
    const double two_g = load(g, ng);
    if (two_g == 0) return false;
    int ca = -1, cb = -1, cr = -1;
    for (int k = 0; k < 3; ++k) {
      if (F(g, k) == va)
        ca = k;
      else if (F(g, k) == vb)
        cb = k;
      else
        cr = k;
    }
    if (ca < 0 || cb < 0 || cr < 0) return false;
    const Vector3d r = x[cr] - x[ca];
    const Vector3d in = (r - r.dot(e) * e).normalized();
    t = (along * e + across * in).normalized();
    face = g;
    n = ng;
    two_a = two_g;
    bary = Vector3d::Zero();
    bary(ca) = 1 - lambda;
    bary(cb) = lambda;
    if (!(remaining > 0)) return true;
  }
  return false;
}

}  // namespace

bool straightest_walk(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3i& TT, int& face,
                      Vector3d& bary, const Vector3d& t, int max_faces) {
  return walk([&](int v) -> Vector3d { return V.row(v).transpose(); }, F, TT, face, bary, t,
              max_faces);
}

}  // namespace mq
