#include "cli/stats_json.h"

#include <cstdio>
#include <string>

namespace mq::cli {

void write_element_counts(JsonWriter& j, const PatchCounts& c) {
  j.value("added", c.added)
      .value("replaced", c.replaced)
      .value("stitched", c.stitched)
      .value("matched", c.matched)
      .value("dropped", c.dropped)
      .value("stitch_fallbacks", c.stitch_fallbacks)
      .value("rejected_intersecting", c.rejected_intersecting);
}

void write_match_counts(JsonWriter& j, const PatchCounts& c) {
  j.begin_object("stitch_failures");
  for (int k = 1; k < kStitchFailureKinds; ++k)
    j.value(stitch_failure_name(static_cast<StitchFailure>(k)), c.stitch_failures[k]);
  // Kind 0 ("none") counts stitches that succeeded but would have intersected a neighbour.
  j.value("intersecting", c.stitch_failures[0]).end_object();
  j.value("pairs", c.pairs).value("relations", c.relations);
}

namespace {

const char* border_name(TextureBorder::Kind k) {
  switch (k) {
    case TextureBorder::Kind::None:
      return "none";
    case TextureBorder::Kind::Segments:
      return "base boundary";
    case TextureBorder::Kind::FlatBox:
      return "flat layer box";
  }
  return "none";
}

std::string histogram_text(const std::vector<int>& h) {
  std::string s;
  for (size_t k = 0; k < h.size(); ++k) {
    if (h[k] == 0) continue;
    if (!s.empty()) s += ", ";
    s += std::to_string(k) + ": " + std::to_string(h[k]);
  }
  return s.empty() ? "-" : s;
}

}  // namespace

void write_structure(JsonWriter& j, const StructureReport& r, const SwatchStructure* swatch,
                     const StructureComparison* comparison, int self_intersecting) {
  j.begin_object("structure")
      .value("elements", static_cast<int>(r.elements.size()))
      .value("border", border_name(r.border))
      .value("median_element_size", r.median_size)
      .value("median_spacing", r.median_spacing)
      .value("rings", r.rings)
      .value("interior_rings", r.interior_rings)
      .value("isolated_rings", r.isolated_rings)
      .value("linked_pairs", static_cast<int>(r.linked_pairs.size()));
  j.begin_array("interior_link_histogram");
  for (const int n : r.interior_link_histogram) j.value("", n);
  j.end_array().begin_array("link_histogram");
  for (const int n : r.link_histogram) j.value("", n);
  j.end_array()
      .value("long_elements", r.long_elements)
      .value("ends", r.ends)
      .value("interior_ends", r.interior_ends)
      .value("area", r.area > 0 ? r.area : std::nan(""))
      .value("density", r.density > 0 ? r.density : std::nan(""))
      .value("density_cells", r.density_cells)
      .value("interior_ends_per_area", r.area > 0 ? r.interior_ends_per_area : std::nan(""));
  if (self_intersecting >= 0) j.value("self_intersecting_elements", self_intersecting);
  if (swatch) {
    j.begin_object("swatch")
        .value("elements", static_cast<int>(swatch->report.elements.size()))
        .value("rings", swatch->report.rings)
        .value("interior_links", swatch->interior_links)
        .value("density", swatch->density)
        .value("median_element_size", swatch->report.median_size);
    j.begin_array("link_histogram");
    for (const int n : swatch->report.link_histogram) j.value("", n);
    j.end_array().end_object();
  }
  if (comparison)
    j.value("share_with_swatch_links", comparison->share_matching)
        .value("density_ratio",
               comparison->density_ratio > 0 ? comparison->density_ratio : std::nan(""))
        .value("linear_scale", comparison->linear_scale)
        .value("stretched_elements", comparison->stretched)
        .value("largest_size_ratio",
               comparison->largest_size > 0 ? comparison->largest_size : std::nan(""));
  j.end_object();
}

void print_structure(const StructureReport& r, const SwatchStructure* swatch,
                     const StructureComparison* comparison) {
  std::printf("rings:             %d (%d interior, border: %s), %d isolated, %zu linked pairs\n",
              r.rings, r.interior_rings, border_name(r.border), r.isolated_rings,
              r.linked_pairs.size());
  if (r.rings > 0) {
    std::printf("links per ring:    interior %s; all %s\n",
                histogram_text(r.interior_link_histogram).c_str(),
                histogram_text(r.link_histogram).c_str());
  }
  if (r.long_elements > 0) {
    std::printf("long elements:     %d, %d ends, %d away from the border", r.long_elements, r.ends,
                r.interior_ends);
    if (r.area > 0) std::printf(" (%.4g per unit area)", r.interior_ends_per_area);
    std::printf("\n");
  }
  if (r.density > 0)
    std::printf("density:           %.6g elements per unit area (%d closed Voronoi cells)\n",
                r.density, r.density_cells);
  if (swatch) {
    if (swatch->report.rings > 0)
      std::printf("swatch:            %d rings, links %s, interior link count %d, density %.6g\n",
                  swatch->report.rings, histogram_text(swatch->report.link_histogram).c_str(),
                  swatch->interior_links, swatch->density);
    else
      std::printf("swatch:            no rings, %d long elements of %zu\n",
                  swatch->report.long_elements, swatch->report.elements.size());
  }
  if (comparison) {
    if (comparison->interior_links >= 0)
      std::printf("structure kept:    %.2f%% of interior rings link %d others, as in the swatch\n",
                  100 * comparison->share_matching, comparison->interior_links);
    if (comparison->density_ratio > 0)
      std::printf("density ratio:     %.2f%% of the swatch's (%.6g output units per swatch unit)\n",
                  100 * comparison->density_ratio, comparison->linear_scale);
    if (comparison->largest_size > 0)
      std::printf(
          "stretched:         %d elements over %.3gx the swatch's element size "
          "(largest %.2fx)\n",
          comparison->stretched, StructureComparison::kStretchedSize, comparison->largest_size);
  }
}

}  // namespace mq::cli
