// Planar mesh quilting, paper section 2: grows a swatch into a seamless L x W layer by seed
// finding, geometry matching, element correspondences, element deformation and merging.
#pragma once

#include <array>
#include <cstdint>

#include "core/common/progress.h"
#include "core/common/stage_timer.h"
#include "core/planar/element_correspondence.h"
#include "core/planar/element_merging.h"
#include "core/planar/geometry_matching.h"
#include "core/planar/patch_quilting.h"

namespace mq {

struct PlanarQuiltingOptions {
  double length = 0;     // L: output extent along x (swatch units)
  double width = 0;      // W: output extent along y
  double cell_size = 0;  // grid cell side; 0 derives it from the swatch's element size
  // Side of the output sub-patch P_out as a fraction of the swatch's shorter side (section 2.4
  // only asks that it be smaller than the swatch); larger values match more context.
  double subpatch_fraction = 0.5;
  // Sub-patch vertices matched in Eq. (3): all of them up to this many, else an evenly strided
  // subset of this size (the paper sums over every vertex; a dense subset ranks offsets the same
  // way at a fraction of the cost; 0 = all).
  int match_points = 1024;
  MatchingOptions matching;
  CorrespondenceOptions correspondence;
  MergeOptions merging;
  bool deform = true;        // section 2.6 element deformation
  bool trim_border = false;  // cut elements crossing the domain border open instead of whole
  uint64_t seed = 1;         // for the epsilon-random offset choice
  // Refuse a job whose output is estimated above this many faces (issue 14: a size that would
  // run for hours or exhaust memory fails at once; about 350 bytes of memory per face).
  double max_faces = 2e7;

  // Throws InvalidInput for a size that is not positive and finite, a negative or non-finite
  // cell size or a sub-patch fraction outside (0, 1].
  void validate() const;
};

// Estimated faces of a length x width layer of the swatch: its pattern's faces per area
// (swatch_face_density) over the layer, at least a swatch wide and long (a strip thinner than
// the swatch still costs a swatch's width), threads with the part that runs past the border.
double estimated_plane_faces(const PreparedSwatch& swatch, double length, double width);

struct PlanarQuiltingStats {
  int iterations = 0;
  double cell_size = 0;
  int grid_nx = 0, grid_ny = 0;
  int window_cells = 0;                 // side of the matched sub-patch, in cells
  long long matched_point_offsets = 0;  // (point, offset) evaluations of Eq. (2)
  PatchCounts counts;    // steps 3-5 over all patches; the first patch's elements count as added
  int removed_post = 0;  // removed in post-processing (outside the domain)
  int trimmed = 0;       // elements cut open at the border (trim_border)
  int faces = 0, vertices = 0, elements = 0;
  StageTimes times;
};

// Where each vertex of a planar quilt comes from (Element::source), in the quilt's vertex order.
struct PlaneSources {
  MatrixX3d point;           // #V by 3: a point of the prepared swatch, in its synthesis frame
  std::vector<int> element;  // #V: the prepared swatch's element it lies on
  // Per element of the quilt, in order (each holds a run of its vertices and of its faces): how
  // many vertices and faces.
  std::vector<int> element_vertices, element_faces;
};

// The default grid cell of the matching (section 2.3's grid): half an element across, and at
// least 8 cells along the swatch's shorter side.
double matching_cell_size(const PreparedSwatch& swatch);

// Runs planar mesh quilting. The swatch's smallest bounding-box side is its thickness; the
// output lies in [0, L] x [0, W] x [0, thickness] (whole elements may cross the border unless
// trim_border). Deterministic for given input, options and evaluator results.
// Throws InvalidInput for impossible parameters (options.validate(), a domain smaller than
// every element of the swatch, a cell larger than the swatch or making too many cells, an
// output too large to hold in memory) and for a swatch prepare_swatch rejects.
// sources (optional): where each output vertex comes from in the swatch (issue 25, swatch
// animation; Element::source), the elements being copies of the swatch's, cut and stitched.
TriMesh quilt_plane(const TriMesh& swatch, const PlanarQuiltingOptions& options,
                    TranslationCostEvaluator& evaluator, PlanarQuiltingStats* stats = nullptr,
                    ProgressSink* progress = nullptr, PlaneSources* sources = nullptr);

}  // namespace mq
