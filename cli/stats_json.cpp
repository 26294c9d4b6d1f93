#include "cli/stats_json.h"

#include <array>
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
      .value("pieces_beyond", c.pieces_beyond)
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

// "not ring-shaped 2, no hole 61, folded 29" (causes with none left out), or "none".
std::string defects_text(const std::array<int, kRingDefects>& d) {
  static const char* const names[kRingDefects] = {"", "not ring-shaped", "no hole", "folded"};
  std::string s;
  for (int k = 1; k < kRingDefects; ++k) {
    if (d[static_cast<size_t>(k)] == 0) continue;
    if (!s.empty()) s += ", ";
    s += std::to_string(d[static_cast<size_t>(k)]) + " " + names[k];
  }
  return s.empty() ? "none" : s;
}

void write_defects(JsonWriter& j, const std::string& key, const std::array<int, kRingDefects>& d) {
  j.begin_object(key);
  for (int k = 1; k < kRingDefects; ++k)
    j.value(ring_defect_name(static_cast<RingDefect>(k)), d[static_cast<size_t>(k)]);
  j.end_object();
}

// The output's own figures (the fields of "structure" that need no swatch).
void write_report(JsonWriter& j, const StructureReport& r) {
  j.value("elements", static_cast<int>(r.elements.size()))
      .value("border", border_name(r.border))
      .value("median_element_size", r.median_size)
      .value("median_spacing", r.median_spacing)
      .value("rings", r.rings)
      .value("interior_rings", r.interior_rings)
      .value("isolated_rings", r.isolated_rings)
      .value("degenerate_rings", r.degenerate_rings())
      .value("interior_degenerate_rings", r.interior_degenerate());
  write_defects(j, "degenerate_by_cause", r.defects);
  write_defects(j, "interior_degenerate_by_cause", r.interior_defects);
  j.value("linked_pairs", static_cast<int>(r.linked_pairs.size()))
      .value("loop_linked_pairs", r.loop_linked_pairs);
  j.begin_array("interior_link_histogram");
  for (const int n : r.interior_link_histogram) j.value("", n);
  j.end_array().begin_array("link_histogram");
  for (const int n : r.link_histogram) j.value("", n);
  j.end_array()
      .value("long_elements", r.long_elements)
      .value("ends", r.ends)
      .value("interior_ends", r.interior_ends)
      .value("closed_long_elements", r.closed_long_elements)
      .value("area", r.area > 0 ? r.area : std::nan(""))
      .value("density", r.density > 0 ? r.density : std::nan(""))
      .value("density_cells", r.density_cells)
      .value("interior_ends_per_area", r.area > 0 ? r.interior_ends_per_area : std::nan(""))
      .value("median_long_length", r.long_elements > 0 ? r.median_long_length : std::nan(""))
      .value("long_length", r.long_length)
      .value("compact_elements", r.compact_elements);
}

// The swatch's figures the output is judged against, per kind.
void write_swatch(JsonWriter& j, const SwatchStructure& swatch) {
  j.begin_object("swatch")
      .value("elements", static_cast<int>(swatch.report.elements.size()))
      .value("rings", swatch.report.rings)
      .value("interior_links", swatch.interior_links)
      .value("density", swatch.density)
      .value("median_element_size", swatch.report.median_size);
  j.begin_array("link_histogram");
  for (const int n : swatch.report.link_histogram) j.value("", n);
  j.end_array().begin_array("kinds");
  for (const SwatchKind& k : swatch.kinds) {
    j.begin_object()
        .value("name", k.name)
        .value("elements", k.elements)
        .value("rings", k.rings)
        .value("ring_kind", k.ring)
        .value("compact", k.compact);
    if (k.ring) j.value("interior_links", k.interior_links);
    j.end_object();
  }
  j.end_array().end_object();
}

// The output against the swatch: links per kind, density, lengths and the shape figures.
void write_comparison(JsonWriter& j, const StructureComparison& c) {
  const ShapeSummary& s = c.shape;
  const auto known = [](double v) { return v > 0 ? v : std::nan(""); };
  j.value("share_with_swatch_links", c.share_matching)
      .value("share_counting_degenerate", c.share_counting_degenerate);
  j.begin_array("share_per_kind");
  for (const KindComparison& k : c.kinds)
    j.begin_object()
        .value("kind", k.kind)
        .value("interior_links", k.interior_links)
        .value("interior_rings", k.interior_rings)
        .value("matching", k.matching)
        .value("degenerate", k.degenerate)
        .value("share", k.share)
        .end_object();
  j.end_array()
      .value("density_ratio", c.density_ratio > 0 ? c.density_ratio : std::nan(""))
      .value("linear_scale", c.linear_scale)
      .value("long_length_ratio", known(c.long_length_ratio))
      .value("interior_ends_per_swatch_area", known(c.interior_ends_per_swatch_area));
  j.begin_object("shape")
      .value("elements", s.elements)
      .value("by_correspondence", s.by_correspondence);
  j.begin_object("size_ratio")
      .value("median", known(s.size_median))
      .value("p90", known(s.size_p90))
      .value("p99", known(s.size_p99))
      .value("max", known(s.size_max))
      .end_object();
  j.begin_object("aspect")
      .value("median", known(s.aspect_median))
      .value("p90", known(s.aspect_p90))
      .value("max", known(s.aspect_max))
      .end_object();
  j.end_object()
      .value("stretched_elements", c.stretched)
      .value("largest_stretch", known(c.largest_stretch))
      .value("largest_size_ratio", known(s.size_max))
      .value("compact_per_length_ratio", known(c.compact_per_length_ratio));
}

}  // namespace

void write_structure(JsonWriter& j, const StructureReport& r, const SwatchStructure* swatch,
                     const StructureComparison* comparison, int self_intersecting) {
  j.begin_object("structure");
  write_report(j, r);
  if (self_intersecting >= 0) j.value("self_intersecting_elements", self_intersecting);
  if (swatch) write_swatch(j, *swatch);
  if (comparison) write_comparison(j, *comparison);
  j.end_object();
}

namespace {

void print_report(const StructureReport& r) {
  std::printf("rings:             %d (%d interior, border: %s), %d isolated, %zu linked pairs\n",
              r.rings, r.interior_rings, border_name(r.border), r.isolated_rings,
              r.linked_pairs.size());
  if (r.rings > 0) {
    std::printf("degenerate rings:  %d (%s), %d of them interior; misses, linked to nothing\n",
                r.degenerate_rings(), defects_text(r.defects).c_str(), r.interior_degenerate());
    std::printf("links per ring:    interior %s, degenerate %d; all %s, degenerate %d\n",
                histogram_text(r.interior_link_histogram).c_str(), r.interior_degenerate(),
                histogram_text(r.link_histogram).c_str(), r.degenerate_rings());
  }
  if (r.long_elements > 0) {
    std::printf("long elements:     %d (%d closed on themselves), %d ends, %d away from the border",
                r.long_elements, r.closed_long_elements, r.ends, r.interior_ends);
    if (r.area > 0) std::printf(" (%.4g per unit area)", r.interior_ends_per_area);
    std::printf("; median length %.4g\n", r.median_long_length);
  }
  if (r.density > 0)
    std::printf("density:           %.6g elements per unit area (%d closed Voronoi cells)\n",
                r.density, r.density_cells);
}

void print_swatch(const SwatchStructure& swatch) {
  if (swatch.report.rings > 0) {
    std::printf("swatch:            %d rings, links %s, interior link count %d, density %.6g\n",
                swatch.report.rings, histogram_text(swatch.report.link_histogram).c_str(),
                swatch.interior_links, swatch.density);
    if (swatch.ring_kinds() > 1) {
      std::string text;
      for (const SwatchKind& k : swatch.kinds)
        if (k.ring)
          text += (text.empty() ? "" : ", ") + k.name + " " + std::to_string(k.interior_links);
      std::printf("swatch kinds:      interior link count per ring kind: %s\n", text.c_str());
    }
  } else {
    std::printf("swatch:            no rings, %d long elements of %zu\n",
                swatch.report.long_elements, swatch.report.elements.size());
  }
}

// Links kept (per kind when the swatch has several ring kinds), density and lengths.
void print_kept(const StructureReport& r, const StructureComparison& c, bool per_kind) {
  if (c.interior_links >= 0) {
    if (per_kind)
      std::printf(
          "structure kept:    %.2f%% of interior rings link as many others as their kind in "
          "the swatch",
          100 * c.share_matching);
    else
      std::printf("structure kept:    %.2f%% of interior rings link %d others, as in the swatch",
                  100 * c.share_matching, c.interior_links);
    std::printf(" (%.2f%% counting degenerate rings' links)\n", 100 * c.share_counting_degenerate);
    if (per_kind)
      for (const KindComparison& k : c.kinds)
        std::printf("  %-16s %.2f%% of %d interior link %d others (%d degenerate)\n",
                    (k.kind + ":").c_str(), 100 * k.share, k.interior_rings, k.interior_links,
                    k.degenerate);
  }
  if (c.density_ratio > 0)
    std::printf("density ratio:     %.2f%% of the swatch's (%.6g output units per swatch unit)\n",
                100 * c.density_ratio, c.linear_scale);
  if (c.long_length_ratio > 0) {
    std::printf("long elements:     median %.2f swatch long elements long", c.long_length_ratio);
    if (c.interior_ends_per_swatch_area > 0)
      std::printf("; %.4g interior ends per swatch unit squared", c.interior_ends_per_swatch_area);
    if (c.compact_per_length_ratio > 0)
      std::printf("; %.3g compact elements per length, %.3f times the swatch's",
                  r.compact_elements / r.long_length, c.compact_per_length_ratio);
    std::printf(" (%.6g output units per swatch unit)\n", c.linear_scale);
  }
}

void print_shape(const StructureComparison& c) {
  const ShapeSummary& s = c.shape;
  if (s.elements <= 0) return;
  std::printf(
      "shape:             %d compact elements (%d by vertex correspondence) against their "
      "swatch element\n",
      s.elements, s.by_correspondence);
  std::printf(
      "  size ratio:      median %.3f, 90th %.3f, 99th %.3f, largest %.3f\n"
      "  aspect:          median %.3f, 90th %.3f, largest %.3f\n",
      s.size_median, s.size_p90, s.size_p99, s.size_max, s.aspect_median, s.aspect_p90,
      s.aspect_max);
  std::printf(
      "stretched:         %d elements over %.3gx the swatch's element along some direction "
      "(largest %.2fx)\n",
      c.stretched, StructureComparison::kStretchedSize, c.largest_stretch);
}

}  // namespace

void print_structure(const StructureReport& r, const SwatchStructure* swatch,
                     const StructureComparison* comparison) {
  print_report(r);
  if (swatch) print_swatch(*swatch);
  if (comparison) {
    print_kept(r, *comparison, swatch && swatch->ring_kinds() > 1);
    print_shape(*comparison);
  }
}

void print_run_structure(const StructureSummary& s, bool full) {
  if (full)
    print_structure(s.output, &s.swatch, &s.comparison);
  else
    print_kept(s.output, s.comparison, s.swatch.ring_kinds() > 1);
}

void write_structure_check(JsonWriter& j, const std::vector<StructureShortfall>& shortfalls) {
  j.begin_object("structure_check").value("passed", shortfalls.empty()).begin_array("shortfalls");
  for (const StructureShortfall& s : shortfalls)
    j.begin_object()
        .value("measure", structure_measure_name(s.measure))
        .value("value", s.value)
        .value("limit", s.limit)
        .value("text", s.text)
        .end_object();
  j.end_array().end_object();
}

void warn_structure(const char* command, const std::vector<StructureShortfall>& shortfalls,
                    const std::string& hint) {
  std::fflush(stdout);  // after the summary when both go to one terminal or file
  for (const StructureShortfall& s : shortfalls)
    std::fprintf(stderr, "meshquilt %s: warning: %s%s%s\n", command, s.text.c_str(),
                 hint.empty() ? "" : "; ", hint.c_str());
}

}  // namespace mq::cli
