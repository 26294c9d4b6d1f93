// Element correspondences, paper section 2.5: vertex-face pairs between the output in the
// overlapping region and the newly placed swatch, pruned, and lifted to element relations.
#pragma once

#include <utility>
#include <vector>

#include "core/planar/overlap_region.h"
#include "core/planar/quilt_elements.h"
#include "core/planar/translation_cost.h"

namespace mq {

struct CorrespondenceOptions {
  double lambda = 1.0;  // Eq. (1) ranking of the closest face
  // A pair is dropped when its distance exceeds this many swatch mean edge lengths (the paper's
  // "much larger than the local edge length average").
  double prune_distance = 2.0;
  // A pair is dropped when the vertex and face normals are opposite: dot product below this.
  double min_normal_dot = 0.0;
};

// One surviving vertex-face pair. Positions are in the output frame (swatch translated by t).
struct VertexFacePair {
  int out_element = -1;
  int out_vertex = -1;  // local to the output element
  int in_element = -1;
  int in_face = -1;  // local to the swatch element
  Vector3d barycentric = Vector3d::Zero();
  Vector3d closest = Vector3d::Zero();  // h_i of section 2.6
  double distance = 0;
};

struct Correspondences {
  std::vector<VertexFacePair> pairs;           // grouped by output element, then vertex
  std::vector<std::pair<int, int>> relations;  // (output element, swatch element), sorted
};

// Pairs every output vertex in `region` (of the listed output elements) with its Eq. (1)-closest
// face of the swatch translated by t, prunes opposite normals and far pairs, and drops the
// relations whose 2D projections do not overlap (with their pairs).
//   output          all output elements; only those listed in `candidates` are visited
//   swatch_faces    face tree over swatch.mesh in the swatch frame (untranslated)
Correspondences find_correspondences(const std::vector<Element>& output,
                                     const std::vector<int>& candidates,
                                     const OverlapRegion& region, const PreparedSwatch& swatch,
                                     const SwatchFaceTree& swatch_faces, const Vector3d& t,
                                     const CorrespondenceOptions& options);

// Whether the xy projections of two elements' triangles overlap, tested on a raster of the
// given resolution (conservative by at most one cell).
bool projections_overlap(const Element& a, const Element& b, double resolution);

// Area of the intersection of the two footprints (xy projections of the triangles) over the
// larger footprint, on the same raster: 1 for the same element placed twice, small when a short
// piece lies along a long one.
double footprint_overlap(const Element& a, const Element& b, double resolution);

}  // namespace mq
