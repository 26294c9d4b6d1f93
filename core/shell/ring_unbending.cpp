#include "core/shell/ring_unbending.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstring>
#include <unordered_map>
#include <utility>

#include "core/common/errors.h"
#include "core/common/fnv1a.h"
#include "core/mesh/mesh_intersections.h"
#include "core/shell/element_grid.h"
#include "core/shell/element_unfolding.h"
#include "core/structure/texture_structure.h"

namespace mq {

void RingUnbendingOptions::validate() const {
  MQ_CHECK(target_fold > 0 && target_fold <= M_PI, InvalidInput,
           "ring unbending: target_fold must be in (0, pi], got ", target_fold);
  for (const double k : keep)
    MQ_CHECK(k >= 0 && k < 1, InvalidInput, "ring unbending: keep must be in [0, 1), got ", k);
  MQ_CHECK(loop_bins >= 8, InvalidInput, "ring unbending: loop_bins must be >= 8, got ", loop_bins);
  MQ_CHECK(kept_links >= 0 && kept_links <= 1, InvalidInput,
           "ring unbending: kept_links must be in [0, 1], got ", kept_links);
}

bool hung_links_hold(const std::vector<int>& placed, const std::vector<int>& hung,
                     double kept_links) {
  MQ_CHECK(placed.size() == hung.size(), InvalidInput, "ring unbending: ", placed.size(),
           " linking numbers as placed against ", hung.size(), " hung");
  int had = 0, kept = 0;
  for (size_t j = 0; j < placed.size(); ++j) {
    if (hung[j] != 0 && placed[j] == 0) return false;
    had += placed[j] != 0;
    kept += hung[j] != 0 && placed[j] != 0;
  }
  return kept >= kept_links * had;
}

namespace {

// How a candidate ended (RingUnbendingStats' counts): no blend within the target fold stayed
// whole, unless a later check turned one down.
enum class UnbendOutcome { SelfCrossing, Unbent, IntoBase, LinksChanged };

struct UnbendCandidate {
  UnbendOutcome outcome = UnbendOutcome::SelfCrossing;
  MatrixX3d V;              // the unbent ring (UnbendOutcome::Unbent)
  Loop loop;                // and its centre loop
  std::vector<int> near;    // ring-shaped neighbours
  std::vector<int> linked;  // per neighbour: the linking number as placed
};

// The centre loop of a ring whose faces are known closed and of genus 1.
std::optional<Loop> loop_of(const MatrixX3d& V, const MatrixX3i& F, int bins) {
  const std::optional<RingBins> b = ring_loop_bins_unchecked(V, F, bins);
  if (!b) return std::nullopt;
  return loop_from_bins(V, *b);
}

// Per element, whether its faces make a ring (closed_genus_one), tested once per distinct face
// matrix: copies of a swatch ring share theirs, and the test (sorting the edges) costs more than
// everything else done to a ring that is not folded.
std::vector<char> ring_faces(const std::vector<const MatrixX3i*>& F,
                             const std::vector<Eigen::Index>& first,
                             const std::vector<char>& skip) {
  const size_t ne = F.size();
  std::vector<std::uint64_t> hash(ne, 0);
  tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
    if (skip[k] || !F[k]) return;
    std::uint64_t h = kFnv1aOffset;
    const Eigen::Index nv = first[k + 1] - first[k];
    fnv1a(h, &nv, sizeof nv);
    fnv1a(h, F[k]->data(), sizeof(int) * static_cast<size_t>(F[k]->size()));
    hash[k] = h;
  });
  // Representatives in element order; a hash match counts only with equal faces.
  std::unordered_map<std::uint64_t, std::vector<size_t>> by_hash;
  std::vector<size_t> rep(ne, 0), reps;
  for (size_t k = 0; k < ne; ++k) {
    if (skip[k] || !F[k]) continue;
    std::vector<size_t>& same = by_hash[hash[k]];
    bool found = false;
    for (const size_t r : same)
      if (first[r + 1] - first[r] == first[k + 1] - first[k] && F[r]->rows() == F[k]->rows() &&
          std::memcmp(F[r]->data(), F[k]->data(), sizeof(int) * F[k]->size()) == 0) {
        rep[k] = r;
        found = true;
        break;
      }
    if (found) continue;
    same.push_back(k);
    rep[k] = k;
    reps.push_back(k);
  }
  std::vector<char> ring(ne, 0);
  tbb::parallel_for(size_t{0}, reps.size(), [&](size_t i) {
    const size_t r = reps[i];
    ring[r] = closed_genus_one(*F[r], first[r + 1] - first[r]);
  });
  for (size_t k = 0; k < ne; ++k)
    if (!skip[k] && F[k]) ring[k] = ring[rep[k]];
  return ring;
}

// The least blend of `placed` towards its fitted flat shape whose fold is within the target,
// if one stays whole, out of the base and keeps every neighbour's linking number.
void unbend(const MatrixX3d& placed, const MatrixX3d& flat, const MatrixX3i& F,
            const std::vector<Loop>& loops, const SignedHeight* ground,
            const PlacementCheckOptions& check, const RingUnbendingOptions& options,
            double reference, UnbendCandidate& c) {
  const std::vector<Eigen::Index> whole = {0, placed.rows()};
  std::pair<int, int> fold{-1, -1};  // the last blend's folded pair, tried first on the next
  // The least blend that keeps options.kept_links of the links but not all: taken only when no
  // blend keeps every linking number as it was.
  std::optional<std::pair<MatrixX3d, Loop>> partly;
  blend_towards_flat(placed, flat, options.keep, [&](MatrixX3d& blend, double) {
    std::optional<Loop> loop = loop_of(blend, F, options.loop_bins);
    if (!loop || ring_fold(*loop) - reference > options.target_fold) return false;
    // A ring hung straighter over a convex edge dips into the base beside it: lifted out whole
    // (its links are checked after). A lift is rigid: it makes no self-crossing.
    if (ground && check_element_heights(*ground, blend, whole, check)[0].below > 0) {
      if (lift_out_of_base(*ground, blend, whole, check, {1})[0].below > 0) {
        c.outcome = UnbendOutcome::IntoBase;
        return false;
      }
      loop = loop_of(blend, F, options.loop_bins);
      if (!loop) return false;
    }
    std::vector<int> now(c.near.size());
    for (size_t j = 0; j < c.near.size(); ++j)
      now[j] = linking_number(*loop, loops[static_cast<size_t>(c.near[j])]);
    const bool all = now == c.linked;
    if (!all && (partly || !hung_links_hold(c.linked, now, options.kept_links))) {
      if (!partly) c.outcome = UnbendOutcome::LinksChanged;
      return false;
    }
    // Last, as the costliest test (a blend whose links change is turned down without it).
    if (self_intersects(blend, F, &fold)) {
      if (!partly) c.outcome = UnbendOutcome::SelfCrossing;
      return false;
    }
    if (!all) {
      partly.emplace(std::move(blend), std::move(*loop));
      return false;
    }
    c.V = std::move(blend);
    c.loop = std::move(*loop);
    c.outcome = UnbendOutcome::Unbent;
    return true;
  });
  if (c.outcome != UnbendOutcome::Unbent && partly) {
    c.V = std::move(partly->first);
    c.loop = std::move(partly->second);
    c.outcome = UnbendOutcome::Unbent;
  }
}

}  // namespace

std::vector<char> unbend_folded_rings(MatrixX3d& V, const std::vector<Eigen::Index>& first,
                                      const std::vector<const MatrixX3i*>& F,
                                      const std::vector<const MatrixX3d*>& flat,
                                      const std::vector<char>& skip, const SignedHeight* ground,
                                      const PlacementCheckOptions& check,
                                      const RingUnbendingOptions& options,
                                      RingUnbendingStats* stats, const std::vector<char>* only) {
  options.validate();
  const size_t ne = F.size();
  MQ_CHECK(first.size() == ne + 1 && flat.size() == ne && skip.size() == ne && !first.empty() &&
               first.back() == V.rows() && (!only || only->size() == ne),
           InvalidInput, "ring unbending: ", ne, " elements with ", first.size(), " offsets, ",
           flat.size(), " flat shapes, ", skip.size(), " flags and ", only ? only->size() : ne,
           " candidate flags over ", V.rows(), " vertices");
  const auto rows = [&](size_t k) { return V.middleRows(first[k], first[k + 1] - first[k]); };
  // Every element's centre loop as placed (none: not ring-shaped), and the folded candidates.
  std::vector<Loop> loops(ne);
  std::vector<char> ring = ring_faces(F, first, skip), folded(ne, 0);
  std::vector<double> reference(ne, 0);
  tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
    if (!ring[k]) return;
    const MatrixX3d placed = rows(k);
    std::optional<Loop> loop = loop_of(placed, *F[k], options.loop_bins);
    if (!loop) {
      ring[k] = 0;  // does not surround its mean point
      return;
    }
    const MatrixX3d* shape = flat[k];
    const double fold = ring_fold(*loop);
    // The flat shape's own fold (>= 0) only where the placed one could exceed it by the limit.
    if (shape && shape->rows() == placed.rows() && fold > kFoldLimit && (!only || (*only)[k])) {
      const std::optional<Loop> own = loop_of(*shape, *F[k], options.loop_bins);
      reference[k] = own ? ring_fold(*own) : M_PI;
      folded[k] = fold - reference[k] > kFoldLimit;
    }
    loops[k] = std::move(*loop);
  });
  std::vector<char> grid_skip(ne, 0);
  for (size_t k = 0; k < ne; ++k) grid_skip[k] = !ring[k];
  const ElementGrid grid(V, first, grid_skip);
  std::vector<UnbendCandidate> candidates(ne);
  tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
    if (!folded[k]) return;
    UnbendCandidate& c = candidates[k];
    for (const int j : grid.near(grid.box[k]))
      if (static_cast<size_t>(j) != k) {
        c.near.push_back(j);
        c.linked.push_back(linking_number(loops[k], loops[static_cast<size_t>(j)]));
      }
    unbend(rows(k), *flat[k], *F[k], loops, ground, check, options, reference[k], c);
  });
  // Two unbent neighbours: the later is put back if their linking changed.
  std::vector<char> moved(ne, 0);
  RingUnbendingStats s;
  for (size_t k = 0; k < ne; ++k) {
    UnbendCandidate& c = candidates[k];
    if (!folded[k]) continue;
    ++s.folded;
    for (size_t j = 0; j < c.near.size() && c.outcome == UnbendOutcome::Unbent; ++j) {
      const auto n = static_cast<size_t>(c.near[j]);
      if (n < k && moved[n] && linking_number(c.loop, loops[n]) != c.linked[j])
        c.outcome = UnbendOutcome::LinksChanged;
    }
    if (c.outcome == UnbendOutcome::Unbent) {
      rows(k) = c.V;
      loops[k] = std::move(c.loop);
      moved[k] = 1;
    }
    s.unbent += c.outcome == UnbendOutcome::Unbent;
    s.into_base += c.outcome == UnbendOutcome::IntoBase;
    s.links_changed += c.outcome == UnbendOutcome::LinksChanged;
    s.self_crossing += c.outcome == UnbendOutcome::SelfCrossing;
  }
  if (stats) *stats = s;
  return moved;
}

}  // namespace mq
