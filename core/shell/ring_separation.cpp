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

// The rings in play and what stays fixed while they move: the movable rings' tubes first, then
// the fixed rings they can reach (obstacles); element_of maps a tube to its element, ring_of an
// element to its tube (-1: not in play).
struct RingScene {
  std::vector<int> ring_of, element_of;
  std::vector<Tube> tubes;
  std::vector<char> free;  // per tube: may move
  double travel = 0;       // no loop point of a movable ring ends farther than this from start
  // Tube pairs (i < j, ascending) that can meet; no other pair can contact or change links.
  std::vector<std::pair<int, int>> pairs;
  std::vector<Loop> start_loops;  // per tube: the loop links are judged by, at the start
  std::vector<Loop> start_tubes;  // per tube: its centre loop at the start
};

// The tubes of the movable rings (made in parallel) and how far they may travel.
RingScene movable_rings(const MatrixX3d& V, const std::vector<Eigen::Index>& first,
                        const std::vector<std::optional<RingBins>>& bins,
                        const std::vector<char>& movable, double max_travel) {
  const size_t ne = bins.size();
  RingScene scene;
  scene.ring_of.assign(ne, -1);
  for (size_t k = 0; k < ne; ++k)
    if (bins[k] && movable[k] && first[k + 1] > first[k]) {
      scene.ring_of[k] = static_cast<int>(scene.element_of.size());
      scene.element_of.push_back(static_cast<int>(k));
    }
  scene.tubes.resize(scene.element_of.size());
  tbb::parallel_for(size_t{0}, scene.element_of.size(), [&](size_t i) {
    const size_t k = static_cast<size_t>(scene.element_of[i]);
    scene.tubes[i] = make_tube(V, first[k], first[k + 1], *bins[k]);
  });
  for (const Tube& t : scene.tubes) scene.travel = std::max(scene.travel, max_travel * t.wire);
  return scene;
}

// Adds the obstacles: fixed rings that a movable one can reach, found through a uniform grid of
// the movable tubes' boxes (cell: the median box size).
void add_obstacles(const MatrixX3d& V, const std::vector<Eigen::Index>& first,
                   const std::vector<std::optional<RingBins>>& bins, RingScene& scene) {
  std::vector<Tube>& tubes = scene.tubes;
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
  for (size_t k = 0; k < bins.size(); ++k) {
    if (scene.ring_of[k] >= 0 || !bins[k] || first[k + 1] == first[k]) continue;
    BoundingBox b;
    for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) b.extend(V.row(v).transpose());
    b.min.array() -= scene.travel;
    b.max.array() += scene.travel;
    bool near = false;
    cells(b, [&](unsigned long long c) {
      if (near) return;
      if (const auto it = grid.find(c); it != grid.end())
        for (const int i : it->second) near = near || boxes_meet(b, tubes[size_t(i)].box, 0);
    });
    if (!near) continue;
    scene.ring_of[k] = static_cast<int>(scene.element_of.size());
    scene.element_of.push_back(static_cast<int>(k));
    tubes.push_back(make_tube(V, first[k], first[k + 1], *bins[k]));
  }
}

// Candidate pairs: tubes, not both fixed, whose boxes, grown by the most the rings can travel,
// meet (a sweep along x).
std::vector<std::pair<int, int>> candidate_pairs(const RingScene& scene) {
  const std::vector<Tube>& tubes = scene.tubes;
  const size_t nt = tubes.size();
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> order(nt);
  for (size_t i = 0; i < nt; ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return tubes[a].box.min.x() < tubes[b].box.min.x(); });
  for (size_t x = 0; x < nt; ++x) {
    const Tube& a = tubes[static_cast<size_t>(order[x])];
    for (size_t y = x + 1; y < nt; ++y) {
      const Tube& b = tubes[static_cast<size_t>(order[y])];
      if (b.box.min.x() > a.box.max.x() + 2 * scene.travel) break;
      const int i = std::min(order[x], order[y]), j = std::max(order[x], order[y]);
      if (!scene.free[i] && !scene.free[j]) continue;
      if (boxes_meet(a.box, b.box, 2 * scene.travel)) pairs.emplace_back(i, j);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// The loops links are judged by where the rings start (link_bins, else the tube's own loop),
// and the tubes' loops there.
void record_start(const MatrixX3d& V, const std::vector<Eigen::Index>& first,
                  const std::vector<std::optional<RingBins>>& link_bins, RingScene& scene) {
  const size_t nt = scene.tubes.size();
  scene.start_loops.resize(nt);
  tbb::parallel_for(size_t{0}, nt, [&](size_t i) {
    const size_t k = static_cast<size_t>(scene.element_of[i]);
    scene.start_loops[i] =
        link_bins[k]
            ? loop_from_bins(V.middleRows(first[k], first[k + 1] - first[k]), *link_bins[k])
            : scene.tubes[i].loop;
  });
  scene.start_tubes.resize(nt);
  for (size_t i = 0; i < nt; ++i) scene.start_tubes[i] = scene.tubes[i].loop;
}

// Position-based rigid bodies (Jacobi iterations with averaged corrections): each iteration
// sums every contact's correction per ring in pair order (the same sums whatever the threads),
// then moves each ring by the mean, capped at max_step and kept within max_travel.
class TubeSolver {
 public:
  TubeSolver(RingScene& scene, const RingSeparationOptions& options)
      : scene_(scene),
        options_(options),
        nt_(scene.tubes.size()),
        contacts_(scene.pairs.size()),
        grounded_(nt_),
        stepped_(nt_, 1),
        touched_(nt_, 0) {}

  // Iterates until no tubes overlap and none sinks into the ground, or max_iterations.
  void run(RingSeparationStats& stats) {
    int overlapping = find_contacts();
    stats.overlaps_before = overlapping;
    // Only rings that touch another are moved; the base then keeps them out of it.
    int sinking = overlapping > 0 ? find_ground() : 0;
    for (int it = 0; it < options_.max_iterations && overlapping + sinking > 0; ++it) {
      ++stats.iterations;
      iterate();
      overlapping = find_contacts();
      sinking = find_ground();
    }
    stats.overlaps_after = overlapping;
  }
  // Per tube: moved in some iteration.
  const std::vector<char>& touched() const { return touched_; }

 private:
  // Rings that moved in the last iteration: only their pairs' contacts can have changed.
  int find_contacts() {
    const auto& pairs = scene_.pairs;
    tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t p) {
      if (stepped_[pairs[p].first] || stepped_[pairs[p].second])
        tube_contacts(scene_.tubes[pairs[p].first], scene_.tubes[pairs[p].second],
                      options_.clearance, contacts_[p]);
    });
    int overlapping = 0;
    for (const auto& c : contacts_) overlapping += !c.empty();
    return overlapping;
  }
  // Contacts of the movable tubes with the base (options.ground), found again for those that
  // moved.
  int find_ground() {
    if (!options_.ground) return 0;
    tbb::parallel_for(size_t{0}, nt_, [&](size_t i) {
      if (scene_.free[i] && stepped_[i])
        ground_contacts(scene_.tubes[i], *options_.ground, grounded_[i]);
    });
    int sinking = 0;
    for (size_t i = 0; i < nt_; ++i) sinking += scene_.free[i] && !grounded_[i].empty();
    return sinking;
  }
  void iterate() {
    dx_.assign(nt_, Vector3d::Zero());
    dw_.assign(nt_, Vector3d::Zero());
    count_.assign(nt_, 0);
    inverse_inertia_.resize(nt_);
    tbb::parallel_for(size_t{0}, nt_, [&](size_t i) {
      if (scene_.free[i]) inverse_inertia_[i] = loop_inertia(scene_.tubes[i]).inverse();
    });
    for (size_t p = 0; p < scene_.pairs.size(); ++p) add_pair_corrections(p);
    for (size_t i = 0; i < nt_; ++i)
      if (scene_.free[i])
        for (const Contact& c : grounded_[i]) add_ground_correction(i, c);
    std::fill(stepped_.begin(), stepped_.end(), 0);
    tbb::parallel_for(size_t{0}, nt_, [&](size_t i) { step_ring(i); });
  }
  void add_pair_corrections(size_t p) {
    const int a = scene_.pairs[p].first, b = scene_.pairs[p].second;
    const std::vector<Tube>& tubes = scene_.tubes;
    for (const Contact& c : contacts_[p]) {
      const Vector3d ra = c.on_a - tubes[a].centre, rb = c.on_b - tubes[b].centre;
      const Vector3d ca = ra.cross(c.normal), cb = rb.cross(c.normal);
      const double wa = scene_.free[a] ? 1 + ca.dot(inverse_inertia_[a] * ca) : 0;
      const double wb = scene_.free[b] ? 1 + cb.dot(inverse_inertia_[b] * cb) : 0;
      if (!(wa + wb > 0)) continue;
      const double lambda = c.depth / (wa + wb);
      if (scene_.free[a]) {
        dx_[a] += lambda * c.normal;
        dw_[a] += inverse_inertia_[a] * (ra.cross(lambda * c.normal));
        ++count_[a];
      }
      if (scene_.free[b]) {
        dx_[b] -= lambda * c.normal;
        dw_[b] -= inverse_inertia_[b] * (rb.cross(lambda * c.normal));
        ++count_[b];
      }
    }
  }
  // A contact with the base, which does not move: ring i takes all of the correction.
  void add_ground_correction(size_t i, const Contact& c) {
    const Vector3d r = c.on_a - scene_.tubes[i].centre, cr = r.cross(c.normal);
    const double lambda = c.depth / (1 + cr.dot(inverse_inertia_[i] * cr));
    dx_[i] += lambda * c.normal;
    dw_[i] += inverse_inertia_[i] * (r.cross(lambda * c.normal));
    ++count_[i];
  }
  void step_ring(size_t i) {
    if (!scene_.free[i] || count_[i] == 0) return;
    touched_[i] = 1;
    Tube& t = scene_.tubes[i];
    Vector3d step = dx_[i] / count_[i], turn = dw_[i] / count_[i];
    // Largest move of a loop point: the translation plus the turn times the ring's reach.
    const double move = step.norm() + turn.norm() * t.reach;
    const double cap = options_.max_step * t.wire;
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
        if ((p - scene_.start_tubes[i][k]).norm() > options_.max_travel * t.wire) return false;
      }
      return true;
    };
    for (int halving = 0; !within(R, step); ++halving) {
      if (halving == 4) return;
      step *= 0.5;
      turn *= 0.5;
      R = rotation_of(turn);
    }
    stepped_[i] = 1;
    for (Vector3d& p : t.loop) p = t.centre + step + R * (p - t.centre);
    t.rotation = (R * t.rotation).eval();
    t.translation = R * (t.translation - t.centre) + t.centre + step;
    t.centre += step;
    t.update_box();
  }

  RingScene& scene_;
  const RingSeparationOptions& options_;
  const size_t nt_;
  std::vector<std::vector<Contact>> contacts_;  // per pair
  std::vector<std::vector<Contact>> grounded_;  // per tube
  std::vector<char> stepped_, touched_;
  std::vector<Vector3d> dx_, dw_;
  std::vector<int> count_;
  std::vector<Eigen::Matrix3d> inverse_inertia_;
};

// Links kept: a ring whose linking with any neighbour changed goes back where it was (and so
// may its neighbours, in turn), until nothing changes. Returns per tube: at its start.
std::vector<char> revert_changed_links(const RingScene& scene, const std::vector<char>& touched,
                                       RingSeparationStats& stats) {
  const size_t nt = scene.tubes.size();
  const auto& pairs = scene.pairs;
  std::vector<char> at_start(nt, 0);
  for (size_t i = 0; i < nt; ++i)
    if (!scene.free[i] || !touched[i]) at_start[i] = 1;
  const auto link_loop = [&](size_t i) {
    if (at_start[i]) return scene.start_loops[i];
    Loop l = scene.start_loops[i];
    for (Vector3d& p : l) p = scene.tubes[i].rotation * p + scene.tubes[i].translation;
    return l;
  };
  std::vector<char> was_linked(pairs.size(), 0);
  tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t p) {
    const int a = pairs[p].first, b = pairs[p].second;
    if (at_start[a] && at_start[b]) return;
    was_linked[p] = linked(scene.start_loops[a], scene.start_loops[b]);
  });
  for (bool any = true; any;) {
    std::vector<char> changed(pairs.size(), 0);
    tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t p) {
      const int a = pairs[p].first, b = pairs[p].second;
      if (at_start[a] && at_start[b]) return;
      changed[p] =
          linked(link_loop(size_t(a)), link_loop(size_t(b))) != static_cast<bool>(was_linked[p]);
    });
    any = false;
    for (size_t p = 0; p < pairs.size(); ++p) {
      if (!changed[p]) continue;
      for (const int i : {pairs[p].first, pairs[p].second})
        if (!at_start[i]) {
          at_start[i] = 1;
          ++stats.reverted;
          any = true;
        }
    }
  }
  return at_start;
}

}  // namespace

void RingSeparationOptions::validate() const {
  MQ_CHECK(max_iterations >= 0 && std::isfinite(clearance) && clearance >= 0 &&
               std::isfinite(max_step) && max_step > 0 && std::isfinite(max_travel) &&
               max_travel >= 0,
           InvalidInput, "ring separation options: iterations, clearance and travel must be >= 0 ",
           "and the step > 0, all finite");
}

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
  options.validate();
  RingSeparationStats stats;
  std::vector<char> moved(ne, 0);
  RingScene scene = movable_rings(V, first, bins, movable, options.max_travel);
  if (!scene.tubes.empty()) {
    add_obstacles(V, first, bins, scene);
    const size_t nt = scene.tubes.size();
    stats.rings = static_cast<int>(nt);
    scene.free.resize(nt);
    for (size_t i = 0; i < nt; ++i) scene.free[i] = movable[size_t(scene.element_of[i])];
    scene.pairs = candidate_pairs(scene);
    record_start(V, first, link_bins, scene);
    TubeSolver solver(scene, options);
    solver.run(stats);
    const std::vector<char> at_start = revert_changed_links(scene, solver.touched(), stats);
    for (size_t i = 0; i < nt; ++i) {
      if (at_start[i]) continue;
      const size_t k = static_cast<size_t>(scene.element_of[i]);
      const Tube& t = scene.tubes[i];
      for (Eigen::Index v = first[k]; v < first[k + 1]; ++v)
        V.row(v) = (t.rotation * V.row(v).transpose() + t.translation).transpose();
      moved[k] = 1;
      ++stats.moved;
    }
  }
  if (stats_out) *stats_out = stats;
  return moved;
}

}  // namespace mq
