#include "core/shell/ring_separation.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/mesh/segment_distance.h"

namespace mq {

namespace {

// A ring as the solver sees it: its centre loop, the tube's radius per loop segment, and its
// rigid motion so far (x = rotation * x0 + translation).
struct Tube {
  Loop loop;
  std::vector<double> radius;  // per segment k (point k to k + 1)
  double wire = 0;             // median segment radius
  double reach = 0;            // largest distance of a loop point from the centre
  Vector3d centre = Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vector3d translation = Vector3d::Zero();
  BoundingBox box;  // of the tube (loop grown by its largest radius)
  void update_box() {
    box = BoundingBox();
    const double r = *std::max_element(radius.begin(), radius.end());
    for (const Vector3d& p : loop) box.extend(p);
    box.min.array() -= r;
    box.max.array() += r;
  }
};

Tube make_tube(const MatrixX3d& V, Eigen::Index v0, Eigen::Index v1, const RingBins& bins) {
  Tube t;
  const MatrixX3d X = V.middleRows(v0, v1 - v0);
  t.loop = loop_from_bins(X, bins);
  const int n = bins.count;
  // Each vertex's distance to the two segments at its loop point: the tube's radius there.
  // The mean, not the largest: the map flattens a cross section where it compresses a ring,
  // and a circle as wide as the flattened section's long axis found 4 times the overlapping
  // pairs the triangles have (armor job: 1,347 against 335) and kept the rings from settling.
  // What the mean misses is found by the exact test after separation.
  std::vector<double> at_point(static_cast<size_t>(n), 0.0);
  std::vector<int> count(static_cast<size_t>(n), 0);
  for (Eigen::Index v = 0; v < X.rows(); ++v) {
    const int k = bins.of_vertex[static_cast<size_t>(v)];
    if (k < 0) continue;
    const Vector3d p = X.row(v).transpose();
    at_point[k] += std::min(point_segment_distance(p, t.loop[k], t.loop[(k + 1) % n]),
                            point_segment_distance(p, t.loop[(k + n - 1) % n], t.loop[k]));
    ++count[k];
  }
  for (int k = 0; k < n; ++k) at_point[k] /= std::max(count[k], 1);
  t.radius.resize(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) t.radius[k] = std::max(at_point[k], at_point[(k + 1) % n]);
  std::vector<double> sorted = t.radius;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  t.wire = std::max(sorted[static_cast<size_t>(n / 2)], 1e-12);
  for (const Vector3d& p : t.loop) t.centre += p;
  t.centre /= n;
  for (const Vector3d& p : t.loop) t.reach = std::max(t.reach, (p - t.centre).norm());
  t.update_box();
  return t;
}

bool boxes_meet(const BoundingBox& a, const BoundingBox& b, double grow) {
  return (a.min.array() - grow <= b.max.array()).all() &&
         (b.min.array() - grow <= a.max.array()).all();
}

struct Contact {
  Vector3d on_a, on_b;  // closest points of the two centre loops
  Vector3d normal;      // from b towards a
  double depth = 0;     // how much closer the loops are than the tubes and clearance allow
};

// The overlaps of two tubes: for each segment of a, its deepest overlap with a segment of b.
void tube_contacts(const Tube& a, const Tube& b, double clearance, std::vector<Contact>& out) {
  out.clear();
  const double gap = clearance * 0.5 * (a.wire + b.wire);
  if (!boxes_meet(a.box, b.box, gap)) return;
  const size_t na = a.loop.size(), nb = b.loop.size();
  for (size_t i = 0; i < na; ++i) {
    const Vector3d& p0 = a.loop[i];
    const Vector3d& p1 = a.loop[(i + 1) % na];
    BoundingBox si;
    si.extend(p0);
    si.extend(p1);
    const double ri = a.radius[i] + gap;
    if (!boxes_meet(si, b.box, ri)) continue;
    Contact best;
    for (size_t j = 0; j < nb; ++j) {
      const Vector3d& q0 = b.loop[j];
      const Vector3d& q1 = b.loop[(j + 1) % nb];
      const double need = ri + b.radius[j];
      // Quick rejection by the segments' boxes.
      const Vector3d lo = q0.cwiseMin(q1).array() - need, hi = q0.cwiseMax(q1).array() + need;
      if ((p0.cwiseMax(p1).array() < lo.array()).any() ||
          (p0.cwiseMin(p1).array() > hi.array()).any())
        continue;
      double s = 0, t = 0;
      closest_points_on_segments(p0, p1, q0, q1, s, t);
      const Vector3d pa = p0 + s * (p1 - p0), pb = q0 + t * (q1 - q0);
      const double d = (pa - pb).norm();
      const double depth = need - d;
      if (depth <= best.depth) continue;
      best.depth = depth;
      best.on_a = pa;
      best.on_b = pb;
      if (d > 1e-9 * need) {
        best.normal = (pa - pb) / d;
      } else {
        // The loops cross (no gap to push along): apart along the segments' common normal,
        // turned the way the centres lie.
        Vector3d n = (p1 - p0).cross(q1 - q0);
        if (!(n.norm() > 0)) n = a.centre - b.centre;
        n.normalize();
        if (n.dot(a.centre - b.centre) < 0) n = -n;
        best.normal = n;
      }
    }
    if (best.depth > 0) out.push_back(best);
  }
}

// The contacts of a tube with the base: each loop point less than its radius above it, pushed
// out along the way from its closest point on the base (the face's normal when on it).
void ground_contacts(const Tube& t, const SignedHeight& ground, std::vector<Contact>& out) {
  out.clear();
  const size_t n = t.loop.size();
  for (size_t k = 0; k < n; ++k) {
    const Vector3d& p = t.loop[k];
    const double r = std::max(t.radius[k], t.radius[(k + n - 1) % n]);
    ClosestPointHit hit;
    const double h = ground(p, &hit);
    if (!(h < r) || hit.face < 0) continue;
    Contact c;
    c.on_a = p;
    c.on_b = hit.point;
    c.depth = r - h;
    const Vector3d away = h > 0 ? Vector3d(p - hit.point) : Vector3d(hit.point - p);
    c.normal = away.norm() > 1e-12 * r ? Vector3d(away.normalized())
                                       : Vector3d(ground.query().face_normals().row(hit.face));
    out.push_back(c);
  }
}

Eigen::Matrix3d loop_inertia(const Tube& t) {
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  for (const Vector3d& p : t.loop) {
    const Vector3d r = p - t.centre;
    I += r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose();
  }
  I /= static_cast<double>(t.loop.size());
  I += 1e-6 * std::max(I.trace(), 1e-24) * Eigen::Matrix3d::Identity();
  return I;
}

Eigen::Matrix3d rotation_of(const Vector3d& w) {
  const double angle = w.norm();
  if (!(angle > 0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

bool linked(const Loop& a, const Loop& b) { return std::abs(linking_number(a, b)) >= 1; }

}  // namespace

std::vector<char> separate_rings(MatrixX3d& V, const std::vector<Eigen::Index>& first,
                                 const std::vector<std::optional<RingBins>>& bins,
                                 const std::vector<std::optional<RingBins>>& link_bins,
                                 const std::vector<char>& movable,
                                 const RingSeparationOptions& options,
                                 RingSeparationStats* stats_out) {
  const size_t ne = bins.size();
  MQ_CHECK(first.size() == ne + 1 && movable.size() == ne && link_bins.size() == ne, InvalidInput,
           "separate_rings: ", first.size(), " offsets, ", bins.size(), " binnings and ",
           movable.size(), " flags do not describe the same elements");
  MQ_CHECK(ne == 0 || first.back() == V.rows(), InvalidInput, "separate_rings: the offsets end at ",
           ne ? first.back() : 0, ", V has ", V.rows(), " rows");
  RingSeparationStats stats;
  std::vector<char> moved(ne, 0);
  // The rings in play: the movable ones and every ring whose tube box meets theirs.
  std::vector<int> ring_of(ne, -1);
  std::vector<int> element_of;
  std::vector<Tube> tubes;
  for (size_t k = 0; k < ne; ++k)
    if (bins[k] && movable[k] && first[k + 1] > first[k]) {
      ring_of[k] = static_cast<int>(element_of.size());
      element_of.push_back(static_cast<int>(k));
    }
  if (element_of.empty()) {
    if (stats_out) *stats_out = stats;
    return moved;
  }
  {
    std::vector<Tube> made(element_of.size());
    tbb::parallel_for(size_t{0}, element_of.size(), [&](size_t i) {
      const size_t k = static_cast<size_t>(element_of[i]);
      made[i] = make_tube(V, first[k], first[k + 1], *bins[k]);
    });
    tubes = std::move(made);
  }
  // No loop point of a movable ring ends farther than this from where it started.
  double travel = 0;
  for (const Tube& t : tubes) travel = std::max(travel, options.max_travel * t.wire);
  // Obstacles: fixed rings that a movable one can reach, found through a uniform grid of the
  // movable tubes' boxes (cell: the median box size).
  {
    std::vector<double> sizes;
    sizes.reserve(tubes.size());
    for (const Tube& t : tubes) sizes.push_back(t.box.extent().maxCoeff());
    std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
    const double cell = std::max(sizes[sizes.size() / 2], 1e-12);
    const auto key = [&](long long x, long long y, long long z) {
      return static_cast<unsigned long long>(x) * 0x9E3779B97F4A7C15ull ^
             static_cast<unsigned long long>(y) * 0xC2B2AE3D27D4EB4Full ^
             static_cast<unsigned long long>(z) * 0x165667B19E3779F9ull;
    };
    std::unordered_map<unsigned long long, std::vector<int>> grid;
    const auto cells = [&](const BoundingBox& b, auto&& visit) {
      const auto lo = (b.min / cell).array().floor().cast<long long>().eval();
      const auto hi = (b.max / cell).array().floor().cast<long long>().eval();
      for (long long x = lo(0); x <= hi(0); ++x)
        for (long long y = lo(1); y <= hi(1); ++y)
          for (long long z = lo(2); z <= hi(2); ++z) visit(key(x, y, z));
    };
    for (size_t i = 0; i < tubes.size(); ++i)
      cells(tubes[i].box, [&](unsigned long long c) { grid[c].push_back(static_cast<int>(i)); });
    for (size_t k = 0; k < ne; ++k) {
      if (ring_of[k] >= 0 || !bins[k] || first[k + 1] == first[k]) continue;
      BoundingBox b;
      for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) b.extend(V.row(v).transpose());
      b.min.array() -= travel;
      b.max.array() += travel;
      bool near = false;
      cells(b, [&](unsigned long long c) {
        if (near) return;
        if (const auto it = grid.find(c); it != grid.end())
          for (const int i : it->second)
            near = near || boxes_meet(b, tubes[static_cast<size_t>(i)].box, 0);
      });
      if (!near) continue;
      ring_of[k] = static_cast<int>(element_of.size());
      element_of.push_back(static_cast<int>(k));
      tubes.push_back(make_tube(V, first[k], first[k + 1], *bins[k]));
    }
  }
  const size_t nt = tubes.size();
  stats.rings = static_cast<int>(nt);
  std::vector<char> free(nt, 0);
  for (size_t i = 0; i < nt; ++i) free[i] = movable[static_cast<size_t>(element_of[i])];

  // Candidate pairs: tubes whose boxes, grown by the most the rings can travel, meet. No other
  // pair's loops can come near each other, so no other pair can contact or change its links.
  std::vector<std::pair<int, int>> pairs;
  {
    std::vector<int> order(nt);
    for (size_t i = 0; i < nt; ++i) order[i] = static_cast<int>(i);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return tubes[a].box.min.x() < tubes[b].box.min.x(); });
    for (size_t x = 0; x < nt; ++x) {
      const Tube& a = tubes[static_cast<size_t>(order[x])];
      for (size_t y = x + 1; y < nt; ++y) {
        const Tube& b = tubes[static_cast<size_t>(order[y])];
        if (b.box.min.x() > a.box.max.x() + 2 * travel) break;
        const int i = std::min(order[x], order[y]), j = std::max(order[x], order[y]);
        if (!free[i] && !free[j]) continue;
        if (boxes_meet(a.box, b.box, 2 * travel)) pairs.emplace_back(i, j);
      }
    }
    std::sort(pairs.begin(), pairs.end());
  }
  // The loops links are judged by, where the rings start (moved rigidly with them below).
  std::vector<Loop> start_loops(nt);
  tbb::parallel_for(size_t{0}, nt, [&](size_t i) {
    const size_t k = static_cast<size_t>(element_of[i]);
    start_loops[i] = link_bins[k] ? loop_from_bins(V.middleRows(first[k], first[k + 1] - first[k]),
                                                   *link_bins[k])
                                  : tubes[i].loop;
  });
  const auto link_loop = [&](size_t i) {
    Loop l = start_loops[i];
    for (Vector3d& p : l) p = tubes[i].rotation * p + tubes[i].translation;
    return l;
  };

  std::vector<Loop> start_tubes(nt);
  for (size_t i = 0; i < nt; ++i) start_tubes[i] = tubes[i].loop;
  std::vector<std::vector<Contact>> contacts(pairs.size());
  // Rings that moved in the last iteration: only their pairs' contacts can have changed.
  std::vector<char> stepped(nt, 1);
  const auto find_contacts = [&] {
    tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t p) {
      if (stepped[pairs[p].first] || stepped[pairs[p].second])
        tube_contacts(tubes[pairs[p].first], tubes[pairs[p].second], options.clearance,
                      contacts[p]);
    });
    int overlapping = 0;
    for (const auto& c : contacts) overlapping += !c.empty();
    return overlapping;
  };
  stats.overlaps_before = find_contacts();
  int overlapping = stats.overlaps_before;
  // Contacts of the movable tubes with the base (options.ground), found again for those that
  // moved.
  std::vector<std::vector<Contact>> grounded(nt);
  const auto find_ground = [&] {
    if (!options.ground) return 0;
    tbb::parallel_for(size_t{0}, nt, [&](size_t i) {
      if (free[i] && stepped[i]) ground_contacts(tubes[i], *options.ground, grounded[i]);
    });
    int sinking = 0;
    for (size_t i = 0; i < nt; ++i) sinking += free[i] && !grounded[i].empty();
    return sinking;
  };
  // Only rings that touch another are moved; the base then keeps them out of it.
  int sinking = overlapping > 0 ? find_ground() : 0;
  std::vector<Vector3d> dx(nt), dw(nt);
  std::vector<int> count(nt);
  std::vector<char> touched(nt, 0);
  for (int it = 0; it < options.max_iterations && overlapping + sinking > 0; ++it) {
    ++stats.iterations;
    std::fill(dx.begin(), dx.end(), Vector3d::Zero());
    std::fill(dw.begin(), dw.end(), Vector3d::Zero());
    std::fill(count.begin(), count.end(), 0);
    std::vector<Eigen::Matrix3d> inverse_inertia(nt);
    tbb::parallel_for(size_t{0}, nt, [&](size_t i) {
      if (free[i]) inverse_inertia[i] = loop_inertia(tubes[i]).inverse();
    });
    // Accumulated in pair order: the same sums whatever the threads.
    for (size_t p = 0; p < pairs.size(); ++p) {
      const int a = pairs[p].first, b = pairs[p].second;
      for (const Contact& c : contacts[p]) {
        const Vector3d ra = c.on_a - tubes[a].centre, rb = c.on_b - tubes[b].centre;
        const Vector3d ca = ra.cross(c.normal), cb = rb.cross(c.normal);
        const double wa = free[a] ? 1 + ca.dot(inverse_inertia[a] * ca) : 0;
        const double wb = free[b] ? 1 + cb.dot(inverse_inertia[b] * cb) : 0;
        if (!(wa + wb > 0)) continue;
        const double lambda = c.depth / (wa + wb);
        if (free[a]) {
          dx[a] += lambda * c.normal;
          dw[a] += inverse_inertia[a] * (ra.cross(lambda * c.normal));
          ++count[a];
        }
        if (free[b]) {
          dx[b] -= lambda * c.normal;
          dw[b] -= inverse_inertia[b] * (rb.cross(lambda * c.normal));
          ++count[b];
        }
      }
    }
    for (size_t i = 0; i < nt; ++i) {
      if (!free[i]) continue;
      for (const Contact& c : grounded[i]) {  // the base does not move
        const Vector3d r = c.on_a - tubes[i].centre, cr = r.cross(c.normal);
        const double lambda = c.depth / (1 + cr.dot(inverse_inertia[i] * cr));
        dx[i] += lambda * c.normal;
        dw[i] += inverse_inertia[i] * (r.cross(lambda * c.normal));
        ++count[i];
      }
    }
    std::fill(stepped.begin(), stepped.end(), 0);
    tbb::parallel_for(size_t{0}, nt, [&](size_t i) {
      if (!free[i] || count[i] == 0) return;
      touched[i] = 1;
      Tube& t = tubes[i];
      Vector3d step = dx[i] / count[i], turn = dw[i] / count[i];
      // Largest move of a loop point: the translation plus the turn times the ring's reach.
      const double move = step.norm() + turn.norm() * t.reach;
      const double cap = options.max_step * t.wire;
      if (move > cap) {
        step *= cap / move;
        turn *= cap / move;
      }
      Eigen::Matrix3d R = rotation_of(turn);
      // No loop point farther than max_travel wire radii from where it started: halve the step
      // until it stays within (the last halving leaves the ring where it is).
      const auto within = [&](const Eigen::Matrix3d& rot, const Vector3d& shift) {
        for (size_t k = 0; k < t.loop.size(); ++k) {
          const Vector3d p = t.centre + shift + rot * (t.loop[k] - t.centre);
          if ((p - start_tubes[i][k]).norm() > options.max_travel * t.wire) return false;
        }
        return true;
      };
      for (int halving = 0; !within(R, step); ++halving) {
        if (halving == 4) return;
        step *= 0.5;
        turn *= 0.5;
        R = rotation_of(turn);
      }
      stepped[i] = 1;
      for (Vector3d& p : t.loop) p = t.centre + step + R * (p - t.centre);
      t.rotation = (R * t.rotation).eval();
      t.translation = R * (t.translation - t.centre) + t.centre + step;
      t.centre += step;
      t.update_box();
    });
    overlapping = find_contacts();
    sinking = find_ground();
  }
  stats.overlaps_after = overlapping;

  // Links kept: a ring whose linking with any neighbour changed goes back where it was (and so
  // may its neighbours, in turn), until nothing changes.
  std::vector<char> at_start(nt, 0);
  for (size_t i = 0; i < nt; ++i)
    if (!free[i] || !touched[i]) at_start[i] = 1;

  std::vector<char> was_linked(pairs.size(), 0);
  tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t p) {
    const int a = pairs[p].first, b = pairs[p].second;
    if (at_start[a] && at_start[b]) return;
    was_linked[p] = linked(start_loops[a], start_loops[b]);
  });
  for (;;) {
    std::vector<char> changed(pairs.size(), 0);
    tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t p) {
      const int a = pairs[p].first, b = pairs[p].second;
      if (at_start[a] && at_start[b]) return;
      const Loop la = at_start[a] ? start_loops[a] : link_loop(static_cast<size_t>(a));
      const Loop lb = at_start[b] ? start_loops[b] : link_loop(static_cast<size_t>(b));
      changed[p] = linked(la, lb) != static_cast<bool>(was_linked[p]);
    });
    bool any = false;
    for (size_t p = 0; p < pairs.size(); ++p) {
      if (!changed[p]) continue;
      for (const int i : {pairs[p].first, pairs[p].second})
        if (!at_start[i]) {
          at_start[i] = 1;
          ++stats.reverted;
          any = true;
        }
    }
    if (!any) break;
  }
  for (size_t i = 0; i < nt; ++i) {
    if (at_start[i]) continue;
    const size_t k = static_cast<size_t>(element_of[i]);
    for (Eigen::Index v = first[k]; v < first[k + 1]; ++v)
      V.row(v) = (tubes[i].rotation * V.row(v).transpose() + tubes[i].translation).transpose();
    moved[k] = 1;
    ++stats.moved;
  }
  if (stats_out) *stats_out = stats;
  return moved;
}

}  // namespace mq
