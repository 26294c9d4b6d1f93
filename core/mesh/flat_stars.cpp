#include "core/mesh/flat_stars.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>

namespace mq {

namespace {

constexpr double kMinSector = 1e-3;  // radians
constexpr double kMinCosine = 0.1;   // faces within about 84 degrees of the mean normal
constexpr int kMaxStar = 64;

// One face of a star: the corners after the centre in the face's order, a then b.
struct Wedge {
  int a, b;
};

// Whether the wedges round centre c (k of them) project one-to-one (see flat_stars).
bool flat_star(const MatrixX3d& V, int c, const Wedge* w, int k) {
  if (k < 1 || k > kMaxStar) return false;
  const Vector3d x = V.row(c).transpose();
  std::array<Vector3d, kMaxStar> n;
  Vector3d d = Vector3d::Zero();
  for (int i = 0; i < k; ++i) {
    n[static_cast<size_t>(i)] =
        (V.row(w[i].a).transpose() - x).cross(V.row(w[i].b).transpose() - x);
    d += n[static_cast<size_t>(i)];
  }
  const double dn = d.norm();
  if (!(dn > 0)) return false;
  d /= dn;
  for (int i = 0; i < k; ++i)
    if (!(n[static_cast<size_t>(i)].dot(d) >= kMinCosine * n[static_cast<size_t>(i)].norm()))
      return false;
  // One fan: each wedge's b is the next one's a, once; a chain starts at the wedge whose a is
  // no wedge's b.
  std::array<int, kMaxStar> next;
  std::array<char, kMaxStar> has_previous{};
  for (int i = 0; i < k; ++i) {
    next[static_cast<size_t>(i)] = -1;
    for (int j = 0; j < k; ++j)
      if (j != i && w[j].a == w[i].b) {
        if (next[static_cast<size_t>(i)] >= 0) return false;  // two faces follow: not one fan
        next[static_cast<size_t>(i)] = j;
      }
    if (next[static_cast<size_t>(i)] >= 0) {
      if (has_previous[static_cast<size_t>(next[static_cast<size_t>(i)])]) return false;
      has_previous[static_cast<size_t>(next[static_cast<size_t>(i)])] = 1;
    }
  }
  int start = 0, starts = 0;
  for (int i = 0; i < k; ++i)
    if (!has_previous[static_cast<size_t>(i)]) {
      start = i;
      ++starts;
    }
  if (starts > 1) return false;
  const bool cycle = starts == 0;
  // The sectors in the plane normal to d, walked in fan order: each turning positively by
  // kMinSector to pi - kMinSector (its sine at least that of kMinSector), and round the vertex
  // once: the first sector's start direction u0 lies in one sector (half-open) only. The shared
  // edges project alike, so a cycle's sectors tile whole turns and that count is its winding.
  const Vector3d e1 = d.unitOrthogonal(), e2 = d.cross(e1);
  const double min_sine = std::sin(kMinSector);
  const auto planar = [&](int v) {
    const Vector3d p = V.row(v).transpose() - x;
    return Eigen::Vector2d(p.dot(e1), p.dot(e2));
  };
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
  };
  // Each wedge has one successor and one predecessor at most: the walk visits none twice.
  const Eigen::Vector2d u0 = planar(w[start].a);
  Eigen::Vector2d last;
  int visited = 0, containing = 0;
  for (int i = start; visited == 0 || (i >= 0 && i != start); i = next[static_cast<size_t>(i)]) {
    const Eigen::Vector2d ua = planar(w[i].a), ub = planar(w[i].b);
    if (!(cross(ua, ub) >= min_sine * ua.norm() * ub.norm())) return false;
    if (cross(ua, u0) >= 0 && cross(u0, ub) > 0) ++containing;
    last = ub;
    ++visited;
  }
  if (visited != k || containing != 1) return false;
  if (cycle) return true;
  // A chain leaves a gap of at least kMinSector between its end and its start (judged only where
  // that is clear: a gap of 90 to 270 degrees, or one whose sine exceeds kMinSector's).
  return cross(last, u0) >= min_sine * last.norm() * u0.norm() || last.dot(u0) < 0;
}

}  // namespace

std::vector<char> flat_stars(const MatrixX3d& V, const MatrixX3i& F,
                             const std::vector<char>* needed) {
  const auto nv = static_cast<size_t>(V.rows());
  std::vector<char> out(nv, 0);
  const auto want = [&](int v) { return !needed || (*needed)[static_cast<size_t>(v)]; };
  // Each wanted vertex's wedges, in face order.
  std::vector<int> offsets(nv + 1, 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (want(F(f, k))) ++offsets[static_cast<size_t>(F(f, k)) + 1];
  for (size_t v = 0; v < nv; ++v) offsets[v + 1] += offsets[v];
  std::vector<Wedge> wedges(static_cast<size_t>(offsets[nv]));
  {
    std::vector<int> cursor(offsets.begin(), offsets.end() - 1);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int v = F(f, k);
        if (want(v))
          wedges[static_cast<size_t>(cursor[static_cast<size_t>(v)]++)] = {F(f, (k + 1) % 3),
                                                                           F(f, (k + 2) % 3)};
      }
  }
  const auto judge = [&](size_t lo, size_t hi) {
    for (size_t v = lo; v < hi; ++v) {
      const int begin = offsets[v], count = offsets[v + 1] - offsets[v];
      if (count > 0)
        out[v] = flat_star(V, static_cast<int>(v), wedges.data() + begin, count) ? 1 : 0;
    }
  };
  // One element's test runs inside loops that are parallel already: no tasks for it.
  if (F.rows() <= 16384)
    judge(0, nv);
  else
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096),
                      [&](const tbb::blocked_range<size_t>& r) { judge(r.begin(), r.end()); });
  return out;
}

}  // namespace mq
