// Steps 3 to 5 of mesh quilting for one placed patch (paper sections 2.5-2.7): element
// correspondences, element deformation and element merging, in a plane where the swatch has been
// translated by t. Planar quilting runs them in its output plane; surface quilting in the
// flattened local patch. Both present their output through PatchOutput.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "core/common/stage_timer.h"
#include "core/mesh/embree_device.h"
#include "core/planar/element_correspondence.h"
#include "core/planar/element_merging.h"
#include "core/planar/laplacian_deformation.h"

namespace mq {

// The caller's output elements, seen in the patch plane. Ids are the caller's.
class PatchOutput {
 public:
  virtual ~PatchOutput() = default;
  virtual const Element& element(int id) const = 0;
  virtual bool alive(int id) const = 0;
  // Alive elements whose footprint box meets [lo, hi], ascending ids.
  virtual std::vector<int> elements_near(const Vector2d& lo, const Vector2d& hi) const = 0;
  virtual int add(Element e) = 0;
  virtual void replace(int id, Element e) = 0;
  virtual void remove(int id) = 0;
};

struct PatchQuiltingOptions {
  CorrespondenceOptions correspondence;
  MergeOptions merging;
  bool deform = true;  // section 2.6
  // An output element is a swatch element's partner (the same element, to be kept, replaced or
  // stitched) only if its pairs with it cover at least this share of its vertices inside the
  // overlap region. Interlinked rings and crossing threads pair only where they touch; taken
  // as partners, a new ring linked to the output was refused (cut-and-stitch of two different
  // rings fails). 30 x 30 planes of 4-in-1 sheets, interior rings with the swatch's 4 links:
  // --detail 16 3x3 3% at 0, 83% at 0.3, 100% at 0.5 and 0.7; plain weave 26 x 26 unchanged
  // (97 threads at 0 and 0.5, 101 at 0.7).
  double partner_share = 0.5;

  // Throws InvalidInput unless partner_share lies in [0, 1].
  void validate() const;
};

// What one patch did, added to running totals by the caller.
struct PatchCounts {
  long long pairs = 0;            // vertex-face pairs kept
  long long relations = 0;        // element relations kept
  int added = 0;                  // swatch elements without partner added as they are
  int replaced = 0;               // output elements inside the overlap replaced by swatch ones
  int stitched = 0;               // cut-and-stitch merges
  int matched = 0;                // partners that are the same element: output kept
  int dropped = 0;                // swatch elements inside the overlap or with ambiguous partners
  int stitch_fallbacks = 0;       // cut-and-stitch refused: output kept whole
  int pieces_beyond = 0;          // of those, a thread's pieces beyond the overlap added, capped
  int rejected_intersecting = 0;  // candidates that would intersect existing elements
  std::array<int, kStitchFailureKinds> stitch_failures{};  // fallbacks by StitchFailure
};

// What quilt_patch needs besides the swatch's elements, built once per run (borrowed).
struct SwatchQueries {
  const SwatchFaceTree& faces;               // over swatch.mesh in the swatch frame (matching's)
  const EmbreeDevice& embree;                // for the merging's temporary BVHs
  const LaplacianTopologyCache& laplacians;  // the swatch elements' (swatch_topologies)
};

// The Laplacian topologies of the swatch's elements, shared by all their copies.
LaplacianTopologyCache swatch_topologies(const PreparedSwatch& swatch);

// Merges the swatch placed at translation t into `output`. `admissible(e)` says whether a swatch
// element may enter the output at all (e.g. lies at least partly in the domain). Elements are
// only ever added or changed so that no two of them intersect. Times go to the stages
// "correspondence", "deformation" and "merging". `rejected`, when given, receives the indices
// of the swatch elements that could not enter: not admissible, or intersecting the output.
// Throws InvalidInput when options.validate() does, and what the deformation throws
// (deform_elements: InvalidInput, SolverFailure).
void quilt_patch(PatchOutput& output, const PreparedSwatch& swatch, const SwatchQueries& queries,
                 const Vector3d& t, const OverlapRegion& region,
                 const std::function<bool(const Element&)>& admissible,
                 const PatchQuiltingOptions& options, PatchCounts& counts, StageTimes& times,
                 std::vector<int>* rejected = nullptr);

// Adds b's counts to a.
void accumulate(PatchCounts& a, const PatchCounts& b);

}  // namespace mq
