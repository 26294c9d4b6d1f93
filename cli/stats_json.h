// JSON for the counts both synthesis commands report in --stats.
#pragma once

#include "cli/json_writer.h"
#include "core/planar/patch_quilting.h"
#include "core/structure/structure_check.h"
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

// A run's structure after its summary: every figure (print_structure) when `full` (--stats),
// else only the kept-structure lines (links, density, long elements) its own check judges.
void print_run_structure(const StructureSummary& s, bool full);

// Writes "structure_check": whether the result is within core/structure/structure_check's
// limits ("passed") and each figure outside them (measure, value, limit, text).
void write_structure_check(JsonWriter& j, const std::vector<StructureShortfall>& shortfalls);

// Each shortfall as a line "meshquilt COMMAND: warning: TEXT; HINT" on stderr (shown with
// --quiet too: a result outside the limits is never reported as a plain success).
void warn_structure(const char* command, const std::vector<StructureShortfall>& shortfalls,
                    const std::string& hint);

}  // namespace mq::cli
