#include "core/planar/patch_quilting.h"

#include <algorithm>
#include <map>

#include "core/mesh/mesh_intersections.h"
#include "core/planar/laplacian_deformation.h"

namespace mq {

namespace {

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

}  // namespace

void accumulate(PatchCounts& a, const PatchCounts& b) {
  a.pairs += b.pairs;
  a.relations += b.relations;
  a.added += b.added;
  a.replaced += b.replaced;
  a.stitched += b.stitched;
  a.matched += b.matched;
  a.dropped += b.dropped;
  a.stitch_fallbacks += b.stitch_fallbacks;
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
  if (rejected) rejected->clear();
  const double mean_edge = swatch.mean_edge_length;
  // Step 3 (section 2.5): correspondences in the overlapping region.
  Correspondences corr;
  std::vector<Element> moved(swatch.elements.size());
  std::vector<Element> frame;  // output elements near the patch, indexed like `near`
  std::vector<int> near;
  {
    ScopedStageTimer timer(times, "correspondence");
    for (size_t i = 0; i < moved.size(); ++i) {
      moved[i] = swatch.elements[i];
      moved[i].translate(t);
    }
    near = output.elements_near(region.patch_lo(), region.patch_hi());
    frame.reserve(near.size());
    std::vector<int> local(near.size());
    for (size_t k = 0; k < near.size(); ++k) {
      frame.push_back(output.element(near[k]));
      local[k] = static_cast<int>(k);
    }
    corr = find_correspondences(frame, local, region, swatch, queries.faces, t,
                                options.correspondence);
    counts.pairs += static_cast<long long>(corr.pairs.size());
    counts.relations += static_cast<long long>(corr.relations.size());
  }

  // Partners of each swatch element. Relations carried by only a few pairs next to a strong one
  // come from elements that merely touch it (crossing threads of a weave, neighbouring rings):
  // they are not the same element and are ignored.
  std::map<std::pair<int, int>, int> pair_count;
  for (const VertexFacePair& p : corr.pairs) ++pair_count[{p.out_element, p.in_element}];
  std::vector<int> strongest(moved.size(), 0);
  for (const auto& [rel, n] : pair_count)
    strongest[rel.second] = std::max(strongest[rel.second], n);
  // A partner must also pair with at least partner_share of the output element's vertices in
  // the overlap region: the same element placed again, not a neighbour it touches (a linked
  // ring, a crossing thread).
  std::vector<int> region_vertices(frame.size(), 0);
  for (size_t k = 0; k < frame.size(); ++k)
    for (int v = 0; v < frame[k].V.rows(); ++v)
      region_vertices[k] += region.contains(frame[k].V.row(v).transpose());
  std::vector<std::vector<int>> partners(moved.size());
  for (const auto& [k, i] : corr.relations)
    if (4 * pair_count[{k, i}] >= strongest[i] &&
        pair_count[{k, i}] >= options.partner_share * region_vertices[k])
      partners[i].push_back(k);

  // Only elements that step 5 may merge need deforming: a swatch element with a live partner that
  // is not inside the overlap (inside ones are dropped), and an output element that is the one
  // crossing partner of such a swatch element (a stitch candidate). On chain mail most related
  // elements are dropped or kept, and deforming them all took as long as everything else.
  // Which output elements lie wholly in the overlap (used here and by step 5).
  std::vector<char> frame_inside(frame.size());
  for (size_t k = 0; k < frame.size(); ++k) frame_inside[k] = inside(frame[k], region);
  std::vector<char> deform_in(moved.size(), 0), deform_out(frame.size(), 0);
  for (size_t i = 0; i < moved.size(); ++i) {
    std::vector<int> crossing;
    bool any = false;
    for (const int k : partners[i]) {
      if (!output.alive(near[k])) continue;
      any = true;
      if (!frame_inside[k]) crossing.push_back(k);
    }
    if (!any || inside(moved[i], region)) continue;
    deform_in[i] = 1;
    if (crossing.size() == 1) deform_out[crossing[0]] = 1;
  }

  // Step 4 (section 2.6): deform both sides of every relation towards the averaged points.
  std::map<int, Element> deformed_out;  // local index -> deformed copy
  {
    ScopedStageTimer timer(times, "deformation");
    std::map<int, std::vector<LinearConstraint>> out_constraints, in_constraints;
    for (const VertexFacePair& p : corr.pairs) {
      if (!deform_out[p.out_element] && !deform_in[p.in_element]) continue;
      const Vector3d v = frame[p.out_element].V.row(p.out_vertex).transpose();
      const Vector3d target = 0.5 * (v + p.closest);
      if (deform_out[p.out_element])
        out_constraints[p.out_element].push_back(LinearConstraint::point(p.out_vertex, target));
      const auto& f = swatch.elements[p.in_element].F.row(p.in_face);
      if (deform_in[p.in_element])
        in_constraints[p.in_element].push_back(
            LinearConstraint::barycentric(f(0), f(1), f(2), p.barycentric, target));
    }
    if (options.deform) {
      // Section 2.6 aligns elements where they correspond; the rest of a long element (a thread
      // running far out of the overlap) is anchored so it does not swing.
      auto anchored = [&](const Element& e, std::vector<LinearConstraint> cs) {
        const auto anchors = anchor_far_vertices(e.V, e.F, cs, options.merging.deformation_rings);
        cs.insert(cs.end(), anchors.begin(), anchors.end());
        return cs;
      };
      std::vector<DeformationJob> jobs;
      std::vector<std::pair<bool, int>> owners;  // (is output, index)
      for (auto& [k, cs] : out_constraints) {
        jobs.push_back({&frame[k].V, &frame[k].F, anchored(frame[k], std::move(cs))});
        owners.emplace_back(true, k);
      }
      for (auto& [i, cs] : in_constraints) {
        jobs.push_back({&moved[i].V, &moved[i].F, anchored(moved[i], std::move(cs))});
        owners.emplace_back(false, i);
      }
      DeformationOptions d;
      d.mu = options.merging.mu;
      std::vector<MatrixX3d> solved = deform_elements(jobs, d, &queries.laplacians);
      for (size_t j = 0; j < solved.size(); ++j) {
        const auto [is_out, k] = owners[j];
        Element& e = is_out ? deformed_out[k] : moved[k];
        if (is_out) {
          e.F = frame[k].F;
          e.kind = frame[k].kind;
        }
        e.V = std::move(solved[j]);
        e.update();
      }
    }
  }

  // Step 5 (section 2.7): merge.
  ScopedStageTimer timer(times, "merging");
  // Output elements take their deformed shape once they are merged with a partner.
  auto current = [&](int k) -> const Element& {
    auto it = deformed_out.find(k);
    return it == deformed_out.end() ? frame[k] : it->second;
  };
  std::vector<char> busy(frame.size(), 0);
  for (size_t i = 0; i < moved.size(); ++i) {
    const Element& in = moved[i];
    if (!admissible(in)) {
      if (rejected) rejected->push_back(static_cast<int>(i));
      continue;
    }
    std::vector<int> related;  // local indices
    for (const int k : partners[i])
      if (output.alive(near[k])) related.push_back(k);
    if (related.empty()) {
      // No partner: added as it is (if it fits among the existing elements).
      if (fits(output, in, {})) {
        output.add(in);
        ++counts.added;
      } else {
        ++counts.rejected_intersecting;
        if (rejected) rejected->push_back(static_cast<int>(i));
      }
      continue;
    }
    if (inside(in, region)) {
      ++counts.dropped;  // the output already has this element
      continue;
    }
    std::vector<int> replaced, crossing;
    for (const int k : related) (frame_inside[k] && !busy[k] ? replaced : crossing).push_back(k);
    std::vector<int> replaced_ids;
    replaced_ids.reserve(replaced.size());
    for (const int k : replaced) replaced_ids.push_back(near[k]);
    if (crossing.empty()) {
      if (fits(output, in, replaced_ids)) {
        for (const int id : replaced_ids) output.remove(id);
        output.add(in);
        counts.replaced += static_cast<int>(replaced.size());
      } else {
        ++counts.rejected_intersecting;
        if (rejected) rejected->push_back(static_cast<int>(i));
      }
      continue;
    }
    if (crossing.size() != 1 || busy[crossing[0]]) {
      ++counts.dropped;
      continue;
    }
    const int k = crossing[0];
    const Element& base = current(k);
    // The same element placed twice (nearly identical, or mostly the same footprint, as for two
    // apples slightly apart): keep the output one rather than stitching two halves.
    if (elements_coincide(base, in, options.merging.coincidence_tolerance * mean_edge,
                          &queries.embree) ||
        footprint_overlap(base, in, mean_edge) >= options.merging.same_element_overlap) {
      ++counts.matched;
      busy[k] = 1;
      continue;
    }
    StitchFailure why = StitchFailure::None;
    std::optional<Element> joined =
        cut_and_stitch(base, in, region, mean_edge, options.merging, &why, &queries.embree);
    std::vector<int> ignore = replaced_ids;
    ignore.push_back(near[k]);
    if (joined && fits(output, *joined, ignore)) {
      for (const int id : replaced_ids) output.remove(id);
      output.replace(near[k], std::move(*joined));
      busy[k] = 1;
      ++counts.stitched;
    } else {
      ++counts.stitch_fallbacks;
      ++counts.stitch_failures[static_cast<int>(joined ? StitchFailure::None : why)];
    }
  }
}

}  // namespace mq
