// A multi-chart texture atlas of the base mesh: the (u, v) part of the texture space of paper
// section 3.2 (the shell's texture space is this atlas extruded by the shell height).
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

struct TextureAtlasOptions {
  // A face joins a chart only while its normal stays within this cosine of the chart seed's
  // normal (a normal cone of about 60 degrees by default); in (-1, 1).
  double cone_cosine = 0.5;
  // A chart whose LSCM flips a triangle, overlaps itself, or whose worst per-face area distortion
  // exceeds this is re-grown with half its face budget (>= 1).
  double max_area_distortion = 3.0;
  int max_chart_faces = 4000;  // face budget of a chart when first grown (>= 1)
  // Empty space between packed chart bounding boxes, relative to sqrt(total 3D area) (>= 0).
  double gutter = 0.01;
};

// Per-face-corner texture coordinates: vertices on chart borders are split, one UV row per
// (chart, vertex) pair.
//   UV          #UV by 2 texture coordinates, at the 3D scale (each chart's UV area equals its
//               3D area up to LSCM's distortion), packed without overlap into one domain
//   FUV         #F by 3 rows of UV for the corners of each face (same corner order as F)
//   face_chart  #F chart id of each face in [0, num_charts)
//   uv_vertex   #UV base vertex of each UV row
struct TextureAtlas {
  MatrixX2d UV;
  MatrixX3i FUV;
  std::vector<int> face_chart;
  std::vector<int> uv_vertex;
  int num_charts = 0;
};

// Builds the atlas: charts grown from seeds by region growing (priority to faces closest in
// normal to the seed, seeds taken in face order), a face joining only when the chart stays a
// topological disk (it shares one edge and brings a new vertex, or shares two edges) and its
// normal stays in the cone; each chart flattened by lscm() and checked (no flips, no self-overlap,
// bounded area distortion; otherwise re-grown smaller, down to single faces which always succeed),
// then shelf-packed by bounding box, tallest first. Deterministic, independent of the thread count.
//   V  #V by 3 finite positions, F  #F by 3 indices, consistently oriented, no zero-area face
// Throws InvalidInput for bad options, an index out of range, non-finite coordinates, no faces
// or a zero-area face.
TextureAtlas texture_atlas(const MatrixX3d& V, const MatrixX3i& F,
                           const TextureAtlasOptions& options = {});

// Normalised L2 stretch of the atlas (Sander et al. 2001, the 2D version of Eq. 9):
// sqrt(sum_f L2(f)^2 A3(f) / sum A3) * sqrt(sum A_uv / sum A3), >= 1 with equality iff every
// chart is a similarity of one common scale; +infinity if a UV triangle is flipped or flat.
// Throws InvalidInput for mismatched sizes or indices out of range.
double atlas_stretch(const MatrixX3d& V, const MatrixX3i& F, const TextureAtlas& atlas);

// Number of pairs of UV triangles (from any charts) whose interiors overlap, found with a
// uniform grid over triangle bounding boxes; triangles sharing a UV row are tested for overlap
// beyond the shared corner or edge by a strict separating-axis test with tolerance 1e-12
// relative to the domain size. Throws InvalidInput for an index out of range.
//   pairs  optional output: the overlapping pairs (s, t), s < t, ascending
int count_uv_overlaps(const TextureAtlas& atlas, std::vector<std::pair<int, int>>* pairs = nullptr);

}  // namespace mq
