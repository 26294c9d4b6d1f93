#include "cli/stats_json.h"

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

}  // namespace mq::cli
