// 1-to-4 midpoint subdivision: every triangle split at its edge midpoints. The surface is
// unchanged (new vertices lie on the old edges); only the sampling gets finer.
#pragma once

#include "core/mesh.h"

namespace mq {

// One level of midpoint subdivision. Edges shared by several faces get one midpoint each, so
// the result stays watertight where the input was. Normals are not carried over.
// Throws InvalidInput for an index out of range.
TriMesh midpoint_subdivide(const TriMesh& mesh);

// Subdivides until the mean edge length is at most max_mean_edge, or the face count would
// exceed max_faces. Returns the number of levels applied through `levels` when non-null.
TriMesh refine_to_edge_length(const TriMesh& mesh, double max_mean_edge, int max_faces,
                              int* levels = nullptr);

}  // namespace mq
