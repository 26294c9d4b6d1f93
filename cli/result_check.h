// The check every command that embeds a quilt makes before writing (issue 23: no silent wrong
// result): a result with no faces, or one that leaves the base bare, fails with one line.
#pragma once

#include <string>

#include "core/mesh/mesh.h"
#include "core/shell/quilt_embedding.h"

namespace mq::cli {

// Throws InvalidInput ("...; nothing written") when `result` has no faces although `placed`
// elements were placed, or covers less of the base than `min_coverage` times `own_coverage`
// (what the swatch covers of its own footprint), naming the likely cause. `remedy` is what the
// user can change, e.g. "try a smaller --scale".
void check_embedded_result(int placed, const TriMesh& result, const QuiltEmbeddingStats& stats,
                           double min_coverage, double own_coverage, const std::string& remedy);

}  // namespace mq::cli
