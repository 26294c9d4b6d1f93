#include "core/structure/structure_check.h"

#include <cmath>
#include <cstdio>

#include "core/common/errors.h"

namespace mq {

namespace {

// Fewer interior rings (or closed density cells) than this: a share says little of the pattern
// (one ring more or less moves it by 2% or more), so it is not judged. A polygon soup of 186
// open pieces (the gothic chair) has 25-42 interior rings of 2,300, whose share swung from 95%
// to 72% with a change elsewhere that its pictures do not show.
constexpr int kMinJudged = 50;

std::string percent(double fraction) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f%%", 100 * fraction);
  return buffer;
}

std::string fixed(double value, int digits) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

}  // namespace

void StructureCheckOptions::validate() const {
  MQ_CHECK(std::isfinite(min_link_share) && min_link_share >= 0 && min_link_share <= 1,
           InvalidInput, "structure check: the least share of linked rings must be in [0, 1], got ",
           min_link_share);
  MQ_CHECK(std::isfinite(min_density) && std::isfinite(max_density) && min_density > 0 &&
               min_density <= 1 && max_density >= 1,
           InvalidInput, "structure check: the density limits must hold 1 between them, got ",
           min_density, " and ", max_density);
  MQ_CHECK(std::isfinite(min_size) && std::isfinite(max_size) && min_size > 0 && min_size <= 1 &&
               max_size >= 1,
           InvalidInput, "structure check: the size limits must hold 1 between them, got ",
           min_size, " and ", max_size);
  MQ_CHECK(std::isfinite(min_long_length) && min_long_length >= 0, InvalidInput,
           "structure check: the least thread length must be finite and >= 0, got ",
           min_long_length);
}

const char* structure_measure_name(StructureShortfall::Measure measure) {
  switch (measure) {
    case StructureShortfall::Measure::Links:
      return "links";
    case StructureShortfall::Measure::Density:
      return "density";
    case StructureShortfall::Measure::LongLength:
      return "long_length";
    case StructureShortfall::Measure::Size:
      return "size";
  }
  return "links";
}

std::vector<StructureShortfall> check_structure(const StructureSummary& summary,
                                                const StructureCheckOptions& options) {
  options.validate();
  const StructureComparison& comparison = summary.comparison;
  const SwatchStructure& swatch = summary.swatch;
  std::vector<StructureShortfall> out;
  using Measure = StructureShortfall::Measure;
  int rings = 0;
  for (const KindComparison& k : comparison.kinds) rings += k.interior_rings;
  if (swatch.interior_links > 0 && rings >= kMinJudged &&
      comparison.share_matching < options.min_link_share)
    out.push_back({Measure::Links, comparison.share_matching, options.min_link_share,
                   percent(comparison.share_matching) + " of interior rings keep their " +
                       "swatch's links, under " + percent(options.min_link_share)});
  // Threads and vines join or space out by design: density is judged for compact swatches.
  const double d = comparison.density_ratio;
  if (swatch.report.long_elements == 0 && d > 0 && summary.output.density_cells >= kMinJudged &&
      (d < options.min_density || d > options.max_density)) {
    const bool sparse = d < options.min_density;
    out.push_back({Measure::Density, d, sparse ? options.min_density : options.max_density,
                   "the elements are " + percent(d) + " as dense as the swatch's, " +
                       (sparse ? "under " + percent(options.min_density) + " (gaps)"
                               : "over " + percent(options.max_density) + " (crowded)")});
  }
  // Threads cut where patches meet end inside the surface (the local patches' weave on a plane:
  // 117 of 148 ends, the global layout's 19 of 84); on a surface smaller than a few swatch
  // threads they are short and end on its border.
  const double l = comparison.long_length_ratio;
  const StructureReport& output = summary.output;
  if (l > 0 && l < options.min_long_length && 2 * output.interior_ends >= output.ends)
    out.push_back({Measure::LongLength, l, options.min_long_length,
                   "the median thread runs " + fixed(l, 2) + " swatch threads, under " +
                       fixed(options.min_long_length, 1) + " (cut where patches meet)"});
  const ShapeSummary& shape = comparison.shape;
  if (shape.elements >= kMinJudged &&
      (shape.size_median < options.min_size || shape.size_median > options.max_size)) {
    const bool small = shape.size_median < options.min_size;
    out.push_back({Measure::Size, shape.size_median, small ? options.min_size : options.max_size,
                   "the median element is " + fixed(shape.size_median, 2) + "x the swatch's, " +
                       (small ? "under " : "over ") +
                       fixed(small ? options.min_size : options.max_size, 2) + "x"});
  }
  return out;
}

}  // namespace mq
