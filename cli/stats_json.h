// JSON for the counts both synthesis commands report in --stats.
#pragma once

#include "cli/json_writer.h"
#include "core/planar/patch_quilting.h"
#include "core/structure/texture_structure.h"

namespace mq::cli {

// Writes the element outcomes of steps 3-5 as keys of the currently open "elements" object.
void write_element_counts(JsonWriter& j, const PatchCounts& c);

// Writes "stitch_failures" (by reason), "pairs" and "relations" into the open object.
void write_match_counts(JsonWriter& j, const PatchCounts& c);

// Writes "structure": links, ends and density of the output, with the swatch's reference
// figures when `swatch` is given (comparison then holds the output against it).
void write_structure(JsonWriter& j, const StructureReport& r, const SwatchStructure* swatch,
                     const StructureComparison* comparison, int self_intersecting = -1);

// The same as a few plain lines on stdout, each starting with `indent`.
void print_structure(const StructureReport& r, const SwatchStructure* swatch,
                     const StructureComparison* comparison);

}  // namespace mq::cli
