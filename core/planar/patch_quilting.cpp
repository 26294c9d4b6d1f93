#include "core/planar/patch_quilting.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <optional>

#include "core/common/errors.h"
#include "core/mesh/boundary_loops.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/laplacian_deformation.h"

namespace mq {

namespace {

// Pieces under this share of their thread's faces are not kept: two more ends for little
// ground (with a tenth, the gallery's 20 x 20 weave had 88 interior ends and its median thread
// fell to 1.47 swatch threads, under the structure check's 1.5).
constexpr double kMinPieceShare = 0.5;

bool boxes_overlap(const Element& a, const Element& b) {
  return a.lo.x() <= b.hi.x() && b.lo.x() <= a.hi.x() && a.lo.y() <= b.hi.y() &&
         b.lo.y() <= a.hi.y() && a.z_lo <= b.z_hi && b.z_lo <= a.z_hi;
}

// Whether e may join the output: it intersects no live element other than those in `ignore`.
bool fits(const PatchOutput& output, const Element& e, const std::vector<int>& ignore) {
  const TriMesh m = e.mesh();
  for (const int id : output.elements_near(e.lo, e.hi)) {
    if (std::find(ignore.begin(), ignore.end(), id) != ignore.end()) continue;
    const Element& other = output.element(id);
    if (boxes_overlap(other, e) && meshes_intersect(other.mesh(), m)) return false;
  }
  return true;
}

bool inside(const Element& e, const OverlapRegion& region) {
  for (int v = 0; v < e.V.rows(); ++v)
    if (!region.contains(e.V.row(v).transpose())) return false;
  return true;
}

// One patch in flight: the swatch's elements moved by t, the output elements near the patch
// (frame, by local index; near: their output ids) and what steps 3 and 4 found between them.
struct Patch {
  std::vector<Element> moved;  // per swatch element
  std::vector<Element> frame;  // per local index
  std::vector<int> near;       // per local index
  Correspondences corr;
  std::vector<std::vector<int>> partners;  // per swatch element: local indices
  std::vector<char> frame_inside;          // per local index: wholly in the overlap
  std::vector<char> deform_in, deform_out;
  std::map<int, Element> deformed_out;  // local index -> deformed copy
};

// Step 3 (section 2.5): the swatch moved by t and its correspondences with the output elements
// near the patch.
Patch find_patch_correspondences(const PatchOutput& output, const PreparedSwatch& swatch,
                                 const SwatchQueries& queries, const Vector3d& t,
                                 const OverlapRegion& region, const CorrespondenceOptions& options,
                                 PatchCounts& counts) {
  Patch patch;
  patch.moved.resize(swatch.elements.size());
  for (size_t i = 0; i < patch.moved.size(); ++i) {
    patch.moved[i] = swatch.elements[i];
    patch.moved[i].translate(t);
  }
  patch.near = output.elements_near(region.patch_lo(), region.patch_hi());
  patch.frame.reserve(patch.near.size());
  std::vector<int> local(patch.near.size());
  for (size_t k = 0; k < patch.near.size(); ++k) {
    patch.frame.push_back(output.element(patch.near[k]));
    local[k] = static_cast<int>(k);
  }
  patch.corr = find_correspondences(patch.frame, local, region, swatch, queries.faces, t, options);
  counts.pairs += static_cast<long long>(patch.corr.pairs.size());
  counts.relations += static_cast<long long>(patch.corr.relations.size());
  return patch;
}

// Partners of each swatch element. Relations carried by only a few pairs next to a strong one
// come from elements that merely touch it (crossing threads of a weave, neighbouring rings):
// they are not the same element and are ignored. A partner must also pair with at least
// partner_share of the output element's vertices in the overlap region: the same element
// placed again, not a neighbour it touches (a linked ring, a crossing thread).
void find_partners(Patch& patch, const OverlapRegion& region, double partner_share) {
  std::map<std::pair<int, int>, int> pair_count;
  for (const VertexFacePair& p : patch.corr.pairs) ++pair_count[{p.out_element, p.in_element}];
  std::vector<int> strongest(patch.moved.size(), 0);
  for (const auto& [rel, n] : pair_count)
    strongest[rel.second] = std::max(strongest[rel.second], n);
  std::vector<int> region_vertices(patch.frame.size(), 0);
  for (size_t k = 0; k < patch.frame.size(); ++k)
    for (int v = 0; v < patch.frame[k].V.rows(); ++v)
      region_vertices[k] += region.contains(patch.frame[k].V.row(v).transpose());
  patch.partners.assign(patch.moved.size(), {});
  for (const auto& [k, i] : patch.corr.relations)
    if (4 * pair_count[{k, i}] >= strongest[i] &&
        pair_count[{k, i}] >= partner_share * region_vertices[k])
      patch.partners[i].push_back(k);
}

// Only elements that step 5 may merge need deforming: a swatch element with a live partner that
// is not inside the overlap (inside ones are dropped), and an output element that is the one
// crossing partner of such a swatch element (a stitch candidate). On chain mail most related
// elements are dropped or kept, and deforming them all took as long as everything else. Also
// marks which output elements lie wholly in the overlap (used here and by step 5).
void choose_deformed(Patch& patch, const PatchOutput& output, const OverlapRegion& region) {
  patch.frame_inside.resize(patch.frame.size());
  for (size_t k = 0; k < patch.frame.size(); ++k)
    patch.frame_inside[k] = inside(patch.frame[k], region);
  patch.deform_in.assign(patch.moved.size(), 0);
  patch.deform_out.assign(patch.frame.size(), 0);
  for (size_t i = 0; i < patch.moved.size(); ++i) {
    std::vector<int> crossing;
    bool any = false;
    for (const int k : patch.partners[i]) {
      if (!output.alive(patch.near[k])) continue;
      any = true;
      if (!patch.frame_inside[k]) crossing.push_back(k);
    }
    if (!any || inside(patch.moved[i], region)) continue;
    patch.deform_in[i] = 1;
    if (crossing.size() == 1) patch.deform_out[crossing[0]] = 1;
  }
}

// Step 4 (section 2.6): deforms both sides of every relation towards the averaged points. The
// swatch elements are deformed in place, the output ones into patch.deformed_out.
void deform_related(Patch& patch, const PreparedSwatch& swatch, const SwatchQueries& queries,
                    const PatchQuiltingOptions& options) {
  std::map<int, std::vector<LinearConstraint>> out_constraints, in_constraints;
  for (const VertexFacePair& p : patch.corr.pairs) {
    if (!patch.deform_out[p.out_element] && !patch.deform_in[p.in_element]) continue;
    const Vector3d v = patch.frame[p.out_element].V.row(p.out_vertex).transpose();
    const Vector3d target = 0.5 * (v + p.closest);
    if (patch.deform_out[p.out_element])
      out_constraints[p.out_element].push_back(LinearConstraint::point(p.out_vertex, target));
    const auto& f = swatch.elements[p.in_element].F.row(p.in_face);
    if (patch.deform_in[p.in_element])
      in_constraints[p.in_element].push_back(
          LinearConstraint::barycentric(f(0), f(1), f(2), p.barycentric, target));
  }
  if (!options.deform) return;
  // Section 2.6 aligns elements where they correspond; the rest of a long element (a thread
  // running far out of the overlap) is anchored so it does not swing.
  auto anchored = [&](const Element& e, std::vector<LinearConstraint> cs) {
    const auto anchors = anchor_far_vertices(e.V, e.F, cs, options.merging.deformation_rings);
    cs.insert(cs.end(), anchors.begin(), anchors.end());
    return cs;
  };
  std::vector<DeformationJob> jobs;
  std::vector<std::pair<bool, int>> owners;  // (is output, index)
  // Output elements (a thread grown over many patches) are solved near their constraints only.
  for (auto& [k, cs] : out_constraints) {
    jobs.push_back({&patch.frame[k].V, &patch.frame[k].F, std::move(cs),
                    options.merging.deformation_rings, options.merging.solve_margin});
    owners.emplace_back(true, k);
  }
  for (auto& [i, cs] : in_constraints) {
    jobs.push_back({&patch.moved[i].V, &patch.moved[i].F, anchored(patch.moved[i], std::move(cs))});
    owners.emplace_back(false, i);
  }
  DeformationOptions d;
  d.mu = options.merging.mu;
  std::vector<MatrixX3d> solved = deform_elements(jobs, d, &queries.laplacians);
  for (size_t j = 0; j < solved.size(); ++j) {
    const auto [is_out, k] = owners[j];
    Element& e = is_out ? patch.deformed_out[k] : patch.moved[k];
    if (is_out) {
      e.F = patch.frame[k].F;
      e.kind = patch.frame[k].kind;
      e.source = patch.frame[k].source;
      e.source_element = patch.frame[k].source_element;
    }
    e.V = std::move(solved[j]);
    e.update();
  }
}

// Step 5 (section 2.7) for one patch: each admissible swatch element is added (no partner),
// dropped (inside the overlap: the output has it), put in place of the partners wholly inside
// the overlap, kept as its one crossing partner (the same element placed twice) or
// cut-and-stitched with it; never so that two elements intersect.
class PatchMerger {
 public:
  PatchMerger(PatchOutput& output, const Patch& patch, const OverlapRegion& region,
              const SwatchQueries& queries, const MergeOptions& options, double mean_edge,
              PatchCounts& counts)
      : output_(output),
        patch_(patch),
        region_(region),
        queries_(queries),
        options_(options),
        mean_edge_(mean_edge),
        counts_(counts),
        busy_(patch.frame.size(), 0),
        outcomes_(patch.moved.size()) {}

  // What stitch() decides from the two elements alone (coincidence, the cut-and-stitch) depends
  // on nothing merge() changes, so it is worked out beforehand for every admissible swatch
  // element with one partner crossing the overlap, in parallel; merge() then commits the
  // outcomes in order, as before. A pair merge() reaches otherwise (a partner removed on the
  // way) is worked out when reached.
  void prepare(const std::function<bool(const Element&)>& admissible) {
    std::vector<std::pair<int, int>> candidates;  // (swatch element, its crossing partner)
    for (size_t i = 0; i < patch_.moved.size(); ++i) {
      int crossing = -1, count = 0;
      for (const int k : patch_.partners[i])
        if (!patch_.frame_inside[k]) {
          crossing = k;
          ++count;
        }
      if (count == 1 && !inside(patch_.moved[i], region_) && admissible(patch_.moved[i]))
        candidates.emplace_back(static_cast<int>(i), crossing);
    }
    tbb::parallel_for(size_t{0}, candidates.size(), [&](size_t c) {
      const auto [i, k] = candidates[c];
      StitchOutcome& o = outcomes_[i];
      try {
        o = outcome(patch_.moved[i], k);
      } catch (...) {
        o.k = k;
        o.error = std::current_exception();
      }
    });
  }

  // Merges swatch element i; false when it could not enter as it would intersect the output.
  bool merge(size_t i) {
    const Element& in = patch_.moved[i];
    std::vector<int> related;  // local indices
    for (const int k : patch_.partners[i])
      if (output_.alive(patch_.near[k])) related.push_back(k);
    if (related.empty()) return replace(in, {});  // no partner: added as it is, if it fits
    if (inside(in, region_)) {
      ++counts_.dropped;  // the output already has this element
      return true;
    }
    std::vector<int> replaced, crossing;
    for (const int k : related)
      (patch_.frame_inside[k] && !busy_[k] ? replaced : crossing).push_back(k);
    std::vector<int> replaced_ids;
    replaced_ids.reserve(replaced.size());
    for (const int k : replaced) replaced_ids.push_back(patch_.near[k]);
    if (crossing.empty()) return replace(in, replaced_ids);
    if (crossing.size() != 1 || busy_[crossing[0]]) {
      ++counts_.dropped;
      std::vector<int> ids;
      ids.reserve(related.size());
      for (const int k : related) ids.push_back(patch_.near[k]);
      keep_beyond_partners(in, ids);
      return true;
    }
    stitch(i, crossing[0], replaced_ids);
    return true;
  }

 private:
  struct StitchOutcome {
    int k = -1;         // the crossing partner (local index) it is for; -1: not worked out
    bool same = false;  // the same element placed twice: the output's is kept
    std::optional<Element> joined;
    StitchFailure why = StitchFailure::None;
    std::exception_ptr error;
  };

  // stitch()'s decision for swatch element `in` and its crossing partner k.
  StitchOutcome outcome(const Element& in, int k) const {
    StitchOutcome o;
    o.k = k;
    // Output elements take their deformed shape once they are merged with a partner.
    const auto it = patch_.deformed_out.find(k);
    const Element& base = it == patch_.deformed_out.end() ? patch_.frame[k] : it->second;
    // The same element placed twice (nearly identical, or mostly the same footprint, as for two
    // apples slightly apart): keep the output one rather than stitching two halves.
    o.same = elements_coincide(base, in, options_.coincidence_tolerance * mean_edge_,
                               &queries_.embree) ||
             footprint_overlap(base, in, mean_edge_) >= options_.same_element_overlap;
    if (!o.same)
      o.joined = cut_and_stitch(base, in, region_, mean_edge_, options_, &o.why, &queries_.embree);
    return o;
  }

  // Adds `in` in place of the output elements `ids` (none: a plain addition) if it fits.
  bool replace(const Element& in, const std::vector<int>& ids) {
    if (!fits(output_, in, ids)) {
      ++counts_.rejected_intersecting;
      return false;
    }
    for (const int id : ids) output_.remove(id);
    output_.add(in);
    if (ids.empty())
      ++counts_.added;
    else
      counts_.replaced += static_cast<int>(ids.size());
    return true;
  }
  // Joins swatch element i with its crossing partner k (local index), whose place it takes
  // with the partners in `replaced_ids`; or keeps the output's element.
  void stitch(size_t i, int k, const std::vector<int>& replaced_ids) {
    StitchOutcome o = outcomes_[i].k == k ? std::move(outcomes_[i]) : outcome(patch_.moved[i], k);
    if (o.error) std::rethrow_exception(o.error);
    if (o.same) {
      ++counts_.matched;
      busy_[k] = 1;
      return;
    }
    std::optional<Element>& joined = o.joined;
    const StitchFailure why = o.why;
    std::vector<int> ignore = replaced_ids;
    ignore.push_back(patch_.near[k]);
    if (joined && fits(output_, *joined, ignore)) {
      for (const int id : replaced_ids) output_.remove(id);
      output_.replace(patch_.near[k], std::move(*joined));
      busy_[k] = 1;
      ++counts_.stitched;
    } else {
      ++counts_.stitch_fallbacks;
      ++counts_.stitch_failures[static_cast<int>(joined ? StitchFailure::None : why)];
      keep_beyond_partners(patch_.moved[i], {patch_.near[k]});
    }
  }

  // A thread whose stitch is refused (or whose partners are ambiguous) still runs over ground
  // its partners do not reach, which on the plane no later patch is seeded on
  // (MergeOptions::pieces_beyond): dropped whole, it left a stretch of the layer without that
  // direction's threads (the wire job: three threads missing over four spacings). Its faces farther
  // than a thread's width from every partner enter instead, each connected piece capped where it
  // was cut, if it fits: two thread ends a little apart rather than a gap. Compact elements (rings,
  // apples) never enter in part.
  void keep_beyond_partners(const Element& in, const std::vector<int>& partners) {
    // A compact element cut in part is a broken ring or half an apple.
    if (!options_.pieces_beyond || !in.long_footprint()) return;
    const double reach = (in.hi - in.lo).minCoeff() + mean_edge_;
    std::vector<char> covered(static_cast<size_t>(in.V.rows()), 0);
    for (const int id : partners) {
      if (!output_.alive(id)) continue;
      const Element& p = output_.element(id);
      const ClosestPointQuery query(queries_.embree, p.V, p.F);
      const std::vector<ClosestPointHit> hits = query.closest(in.V, reach);
      for (size_t v = 0; v < hits.size(); ++v) covered[v] |= hits[v].face >= 0 ? 1 : 0;
    }
    std::vector<int> beyond;
    for (int f = 0; f < in.F.rows(); ++f)
      if (!covered[static_cast<size_t>(in.F(f, 0))] && !covered[static_cast<size_t>(in.F(f, 1))] &&
          !covered[static_cast<size_t>(in.F(f, 2))])
        beyond.push_back(f);
    if (beyond.empty() || beyond.size() == static_cast<size_t>(in.F.rows())) return;
    const Element part = element_part(in, beyond);
    std::vector<int> component;
    const int pieces = connected_components(part.F, static_cast<int>(part.V.rows()), component);
    for (int c = 0; c < pieces; ++c) {
      std::vector<int> faces;
      for (int f = 0; f < part.F.rows(); ++f)
        if (component[static_cast<size_t>(f)] == c) faces.push_back(f);
      if (static_cast<double>(faces.size()) < kMinPieceShare * static_cast<double>(in.F.rows()))
        continue;
      std::optional<Element> piece = capped(element_part(part, faces));
      if (piece && fits(output_, *piece, {})) {
        output_.add(std::move(*piece));
        ++counts_.pieces_beyond;
      }
    }
  }

  // e with each boundary loop closed by a fan from the loop's centroid; none when its boundary
  // is not a set of simple loops.
  static std::optional<Element> capped(Element e) {
    std::vector<std::vector<int>> loops;
    try {
      loops = boundary_loops(e.F, static_cast<int>(e.V.rows()));
    } catch (const TopologyError&) {
      return std::nullopt;
    }
    const bool sourced = !e.source_element.empty();
    for (const std::vector<int>& loop : loops) {
      const auto c = static_cast<int>(e.V.rows());
      const auto m = static_cast<int>(loop.size());
      Vector3d centre = Vector3d::Zero(), source = Vector3d::Zero();
      for (const int v : loop) {
        centre += e.V.row(v).transpose() / m;
        if (sourced) source += e.source.row(v).transpose() / m;
      }
      e.V.conservativeResize(c + 1, 3);
      e.V.row(c) = centre.transpose();
      if (sourced) {
        e.source.conservativeResize(c + 1, 3);
        e.source.row(c) = source.transpose();
        e.source_element.push_back(e.source_element[static_cast<size_t>(loop.front())]);
      }
      // The loop runs as in its faces: the cap runs each edge the other way.
      const Eigen::Index f0 = e.F.rows();
      e.F.conservativeResize(f0 + m, 3);
      for (int i = 0; i < m; ++i) e.F.row(f0 + i) << c, loop[(i + 1) % m], loop[i];
    }
    e.update();
    return e;
  }

  PatchOutput& output_;
  const Patch& patch_;
  const OverlapRegion& region_;
  const SwatchQueries& queries_;
  const MergeOptions& options_;
  const double mean_edge_;
  PatchCounts& counts_;
  std::vector<char> busy_;               // per local index: already merged with a swatch element
  std::vector<StitchOutcome> outcomes_;  // per swatch element
};

}  // namespace

void PatchQuiltingOptions::validate() const {
  MQ_CHECK(std::isfinite(partner_share) && partner_share >= 0 && partner_share <= 1, InvalidInput,
           "patch quilting: partner_share must lie in [0, 1], got ", partner_share);
}

void accumulate(PatchCounts& a, const PatchCounts& b) {
  a.pairs += b.pairs;
  a.relations += b.relations;
  a.added += b.added;
  a.replaced += b.replaced;
  a.stitched += b.stitched;
  a.matched += b.matched;
  a.dropped += b.dropped;
  a.stitch_fallbacks += b.stitch_fallbacks;
  a.pieces_beyond += b.pieces_beyond;
  a.rejected_intersecting += b.rejected_intersecting;
  for (int k = 0; k < kStitchFailureKinds; ++k) a.stitch_failures[k] += b.stitch_failures[k];
}

LaplacianTopologyCache swatch_topologies(const PreparedSwatch& swatch) {
  LaplacianTopologyCache cache;
  for (const Element& e : swatch.elements) cache.add(e.F, static_cast<int>(e.V.rows()));
  return cache;
}

void quilt_patch(PatchOutput& output, const PreparedSwatch& swatch, const SwatchQueries& queries,
                 const Vector3d& t, const OverlapRegion& region,
                 const std::function<bool(const Element&)>& admissible,
                 const PatchQuiltingOptions& options, PatchCounts& counts, StageTimes& times,
                 std::vector<int>* rejected) {
  options.validate();
  if (rejected) rejected->clear();
  Patch patch;
  {
    ScopedStageTimer timer(times, Stage::Correspondence);
    patch = find_patch_correspondences(output, swatch, queries, t, region, options.correspondence,
                                       counts);
  }
  find_partners(patch, region, options.partner_share);
  choose_deformed(patch, output, region);
  {
    ScopedStageTimer timer(times, Stage::Deformation);
    deform_related(patch, swatch, queries, options);
  }
  ScopedStageTimer timer(times, Stage::Merging);
  PatchMerger merger(output, patch, region, queries, options.merging, swatch.mean_edge_length,
                     counts);
  merger.prepare(admissible);
  for (size_t i = 0; i < patch.moved.size(); ++i) {
    const bool entered = admissible(patch.moved[i]) && merger.merge(i);
    if (!entered && rejected) rejected->push_back(static_cast<int>(i));
  }
}

}  // namespace mq
