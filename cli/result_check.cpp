#include "cli/result_check.h"

#include <cmath>

#include "core/common/errors.h"

namespace mq::cli {

void check_embedded_result(int placed, const TriMesh& result, const QuiltEmbeddingStats& e,
                           double min_coverage, double own_coverage, const std::string& remedy) {
  MQ_CHECK(result.num_faces() > 0, InvalidInput, "all ", placed,
           " elements placed were removed after embedding (",
           e.removed_intersecting + e.removed_self_intersecting,
           " intersecting others or themselves, ", e.removed_below, " inside the base; ", remedy,
           ", or --keep-intersecting); nothing written");
  // Judged against what the swatch covers of its own footprint: a sparse swatch (vines) cannot
  // cover more of the base than of itself.
  const double needed = min_coverage * own_coverage;
  if (e.coverage >= needed) return;
  const int removed = e.removed_intersecting + e.removed_self_intersecting + e.removed_below;
  std::string cause;
  if (removed > placed / 10)
    cause = std::to_string(removed) + " of " + std::to_string(placed) + " elements were removed (" +
            std::to_string(e.removed_intersecting + e.removed_self_intersecting) +
            " intersecting, " + std::to_string(e.removed_below) +
            " inside the base: parts of it closer than the shell height?); " + remedy;
  if (e.fallback_area_share > 0.5)
    cause += std::string(cause.empty() ? "" : "; ") + "the shell map was not built over " +
             std::to_string(static_cast<int>(std::lround(100 * e.fallback_area_share))) +
             "% of the base (" + e.fallback_reason + ")";
  if (cause.empty())
    cause = std::to_string(placed) +
            " elements leave the rest bare: the swatch may be too large for the base's parts (" +
            remedy + ")";
  MQ_THROW(InvalidInput, "only ", 100 * e.coverage, "% of the base is covered, below ",
           100 * needed, "% (--min-coverage ", min_coverage, " of the ", 100 * own_coverage,
           "% the swatch covers of itself): ", cause, "; nothing written");
}

}  // namespace mq::cli
