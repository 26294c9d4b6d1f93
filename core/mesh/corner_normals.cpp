#include "core/mesh/corner_normals.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/errors.h"

namespace mq {
namespace {

constexpr long kMaxValence = 256;

// The cosine bound of smooth_fan for a crease cosine min_cos: half the crease angle less a
// margin far above rounding (then no pairwise dot of the exact test can fall under min_cos);
// above 1 (no fan passes) when that leaves nothing, -1 (every fan) at 180 degrees.
double half_crease_cos(double min_cos) {
  if (min_cos <= -1) return -1;
  const double half = 0.5 * std::acos(std::min(1.0, min_cos)) - 1e-6;
  return half > 0 ? std::cos(half) : 2;
}

// Whether every two faces around a vertex ([b, e) into U's rows) are within the crease angle, so
// that each corner's normal takes them all: checked against their summed normal `all`, each face
// within half the angle of it (min_half_cos, half_crease_cos). Linear instead of quadratic in the
// valence; most vertices of a smooth output pass (the armor's 1.4M).
bool smooth_fan(const MatrixX3d& U, const int* b, const int* e, const Vector3d& all,
                double min_half_cos) {
  const double len = all.norm();
  if (e - b > kMaxValence || !(len > 0)) return false;
  const Vector3d m = all / len;
  for (const int* g = b; g != e; ++g) {
    const Vector3d u = U.row(*g).transpose();
    if (!(u.squaredNorm() > 0) || u.dot(m) < min_half_cos) return false;
  }
  return true;
}

}  // namespace

CornerNormals corner_normals(const MatrixX3d& V, const MatrixX3i& F, double crease_degrees) {
  MQ_CHECK(crease_degrees >= 0 && crease_degrees <= 180, InvalidInput,
           "the crease angle must be in [0, 180] degrees, got ", crease_degrees);
  const Eigen::Index nv = V.rows(), nf = F.rows();
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(F(f, k) >= 0 && F(f, k) < nv, InvalidInput, "face ", f, " has vertex index ",
               F(f, k), " out of range (", nv, " vertices)");
  // Area-weighted (twice the area) and unit face normals.
  MatrixX3d W(nf, 3), U(nf, 3);
  tbb::parallel_for(Eigen::Index(0), nf, [&](Eigen::Index f) {
    const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Vector3d w = (b - a).cross(c - a);
    W.row(f) = w.transpose();
    const double len = w.norm();
    U.row(f) = (len > 0 ? Vector3d(w / len) : Vector3d::Zero()).transpose();
  });
  // Faces around each vertex (CSR), in face order.
  std::vector<int> start(static_cast<size_t>(nv) + 1, 0), faces(static_cast<size_t>(3 * nf));
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++start[static_cast<size_t>(F(f, k)) + 1];
  for (size_t v = 0; v < static_cast<size_t>(nv); ++v) start[v + 1] += start[v];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (Eigen::Index f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) faces[static_cast<size_t>(fill[F(f, k)]++)] = static_cast<int>(f);
  }
  // 180 degrees must take every face, even exactly opposite ones.
  const double min_cos = crease_degrees >= 180 ? -2.0 : std::cos(crease_degrees * M_PI / 180.0);
  const double min_half_cos = half_crease_cos(min_cos);
  // Per vertex its distinct corner normals, appended to its block's list in vertex order (one
  // list per block of vertices, not a vector per vertex: a million small allocations were most
  // of the time for the armor's 1.4M vertices); FN holds local numbers first.
  constexpr Eigen::Index kBlock = 4096;
  std::vector<std::vector<Vector3d>> block_normals(static_cast<size_t>((nv + kBlock - 1) / kBlock));
  std::vector<int> count(static_cast<size_t>(nv), 0);
  MatrixX3i FN(nf, 3);
  tbb::parallel_for(size_t(0), block_normals.size(), [&](size_t block) {
    std::vector<Vector3d>& list = block_normals[block];
    const Eigen::Index v0 = static_cast<Eigen::Index>(block) * kBlock;
    for (Eigen::Index v = v0; v < std::min(nv, v0 + kBlock); ++v) {
      const int* b = faces.data() + start[static_cast<size_t>(v)];
      const int* e = faces.data() + start[static_cast<size_t>(v) + 1];
      Vector3d all = Vector3d::Zero();
      for (const int* g = b; g != e; ++g) all += W.row(*g).transpose();
      const size_t mine = list.size();  // v's normals are list[mine..]
      if (smooth_fan(U, b, e, all, min_half_cos)) {
        // Every corner's sum below takes every face, in the same order: `all`, one normal.
        list.push_back(all.normalized());
        for (const int* f = b; f != e; ++f)
          for (int k = 0; k < 3; ++k)
            if (F(*f, k) == v) FN(*f, k) = 0;
        count[static_cast<size_t>(v)] = 1;
        continue;
      }
      for (const int* f = b; f != e; ++f) {
        Vector3d n = Vector3d::Zero();
        const Vector3d uf = U.row(*f).transpose();
        // Past kMaxValence faces the quadratic test is skipped (one smooth normal): a huge fan
        // must not make writing a file quadratic.
        if (uf.squaredNorm() > 0 && e - b <= kMaxValence)
          for (const int* g = b; g != e; ++g)
            if (uf.dot(U.row(*g).transpose()) >= min_cos) n += W.row(*g).transpose();
        if (!(n.norm() > 0)) n = all;
        n = n.norm() > 0 ? Vector3d(n.normalized()) : Vector3d::UnitZ();
        int id = -1;
        for (size_t i = mine; i < list.size() && id < 0; ++i)
          if (list[i] == n) id = static_cast<int>(i - mine);
        if (id < 0) {
          id = static_cast<int>(list.size() - mine);
          list.push_back(n);
        }
        for (int k = 0; k < 3; ++k)
          if (F(*f, k) == v) FN(*f, k) = id;  // a face repeating v takes one normal for both
      }
      count[static_cast<size_t>(v)] = static_cast<int>(list.size() - mine);
    }
  });
  // Global numbering in vertex order: the blocks' lists one after another.
  std::vector<int> first(static_cast<size_t>(nv) + 1, 0);
  for (size_t v = 0; v < static_cast<size_t>(nv); ++v) first[v + 1] = first[v] + count[v];
  CornerNormals out;
  out.N.resize(first.back(), 3);
  Eigen::Index row = 0;
  for (const std::vector<Vector3d>& list : block_normals)
    for (const Vector3d& n : list) out.N.row(row++) = n.transpose();
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) FN(f, k) += first[static_cast<size_t>(F(f, k))];
  out.FN = std::move(FN);
  return out;
}

}  // namespace mq
