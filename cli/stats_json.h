// JSON for the counts both synthesis commands report in --stats.
#pragma once

#include "cli/json_writer.h"
#include "core/patch_quilting.h"

namespace mq::cli {

// Writes the element outcomes of steps 3-5 as keys of the currently open "elements" object.
void write_element_counts(JsonWriter& j, const PatchCounts& c);

// Writes "stitch_failures" (by reason), "pairs" and "relations" into the open object.
void write_match_counts(JsonWriter& j, const PatchCounts& c);

}  // namespace mq::cli
