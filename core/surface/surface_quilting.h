// Mesh quilting over curved surfaces, paper section 3.1: the base mesh's triangles replace the
// planar grid; each iteration grows a local patch from the most constrained unsynthesised
// triangle, flattens it conformally, runs the planar steps of section 2 in that plane (oriented
// by a guidance field) and stores the new geometry in local coordinates on the base mesh.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/common/progress.h"
#include "core/common/stage_timer.h"
#include "core/mesh/longest_edge_bisection.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/geometry_matching.h"
#include "core/planar/patch_quilting.h"
#include "core/planar/quilt_elements.h"

namespace mq {

// Output geometry in local coordinates over the base mesh: vertex i of an element lies above
// base face `face[i]`, at the point with barycentric coordinates `barycentric.row(i)` of that
// face, at height `height[i]` in [0, shell height] along the surface normal.
struct SurfaceElement {
  MatrixX3i F;             // #F by 3, indices into the element's vertices
  std::vector<int> face;   // #V base faces
  MatrixX3d barycentric;   // #V by 3
  Eigen::VectorXd height;  // #V
  // Optional (#V by 3, or empty): the element as it was placed, in the flat frame of its
  // placement (a rigid copy of its swatch element). The embedding falls back to it, moved
  // rigidly, where the map folds the element through itself.
  MatrixX3d flat;
  int kind = 0;  // index into the swatch's kinds (PreparedSwatch::kinds)
  // Optional (empty face: none): the element as the layout alone places it, where the
  // coordinates above are an even copy of it (core/surface/global_quilting, adaptive placement).
  // The embedding tries it before removing the copy for touching a neighbour: distorted, but in its
  // place among its neighbours.
  struct Alternative {
    std::vector<int> face;   // #V
    MatrixX3d barycentric;   // #V by 3
    Eigen::VectorXd height;  // #V
  } through_layout;
  // Optional (#V by 3 and #V, or empty): where each vertex comes from in the swatch (issue 25,
  // swatch animation; core/shell/swatch_animation): a point on the prepared swatch's element
  // source_element[v] (the swatch scaled to the output, in its synthesis frame), or beyond it
  // along SurfaceQuilt::repeat for the element repeated so. Kept with
  // SurfaceQuiltingOptions::keep_sources by the vine method, the global layout's lattice (each
  // copy's vertices are its swatch element's) and the local patches (an element stitched of two
  // has the sources of both parts: Element::source).
  MatrixX3d source;
  std::vector<int> source_element;
};

// A swatch element repeated end to end along an axis in the quilt (the vine method's stems):
// sources beyond it are wrapped into it. element -1: none.
struct SwatchRepeat {
  int element = -1;
  Vector3d start = Vector3d::Zero();  // where one repeat starts, in the prepared swatch's frame
  Vector3d axis = Vector3d::UnitX();  // unit
  double period = 0;                  // one repeat's length along the axis
};

struct SurfaceQuilt {
  std::vector<SurfaceElement> elements;
  double shell_height = 0;
  TriMesh base;                    // the (refined) base mesh the local coordinates refer to
  TriMesh input_base;              // the base as given, coincident vertices welded (or its proxy)
  Refinement refinement;           // base faces in input_base faces (empty: base is input_base)
  std::vector<std::string> kinds;  // names of SurfaceElement::kind (the swatch's)
  SwatchRepeat repeat;             // how SurfaceElement::source wraps (vines)
  // Elements may be stitched of parts of several swatch copies (the local patches, section 2.7),
  // whose sources then lie apart in the swatch, or overlap for two copies of one element.
  bool stitched = false;
  // Made under a size map: elements at other sizes than the swatch's (a swatch animation's
  // motion is scaled with each element, core/shell/swatch_animation).
  bool sized = false;
  // #V(input_base): the vertex of the base as given each input_base vertex is (empty for a
  // proxy, whose vertices are none of them): how a saved quilt follows the base moved.
  std::vector<int> input_vertex;
  // When input_base is a proxy: the base as given, welded, and its input_vertex, which a saved
  // quilt is located over instead (empty otherwise).
  TriMesh welded_base;
  std::vector<int> welded_input_vertex;
};

// Local coordinates on the refined base expressed on the input base: refined faces are affine
// pieces of their parents, so this is exact.
void to_input_base(const SurfaceQuilt& quilt, int& face, Vector3d& barycentric);

struct SurfaceQuiltingOptions {
  // The swatch is scaled uniformly so that its longer footprint side is `scale` times the base
  // mesh's bounding-box diagonal; its thickness, scaled alike, is the shell height.
  double scale = 0.1;
  // When > 0, replaces `scale`: the swatch's longer footprint side in the base's units (issue
  // 25: a size that masking or extending the base does not change). element_size = scale times
  // the diagonal gives the same job bit for bit.
  double element_size = 0;
  // Unit tangent vector per base face orienting the swatch's x axis; empty: a smooth field.
  MatrixX3d field;
  // Element size per vertex of the base as given, as a factor of the size set by scale or
  // element_size (issue 25, `--size-map`): each > 0, the largest at most kMaxSizeMapRange times
  // the smallest; interpolated over the faces. The global layout (lattices and threads) places its
  // cones for it as a log scale; the local patches take each patch at its seed's size; the vine
  // method takes every distance at the size where it is measured. Empty: one size.
  Eigen::VectorXd size_map;
  static constexpr double kMaxSizeMapRange = 8;
  // Keep where each output vertex comes from in the swatch (SurfaceElement::source), for a swatch
  // animation (issue 25); followed by the vine method, the global layout's lattice and the local
  // patches (not by the global layout's threads or plane quilt).
  bool keep_sources = false;
  // Where long elements may lie (issue 25, `--mask`): per face of the refined base it is
  // handed, whether that face is in; empty: everywhere. The vine method's stems stop at the
  // region's border as at the base's, and leaves lie within it; the global layout's threads end
  // at it (their pieces outside left out), so no long element is kept whole across it. Compact
  // elements are placed everywhere (and then kept or dropped whole by the caller).
  std::function<std::vector<char>(const TriMesh& refined_base)> region;
  // When the swatch given is one at lower detail (core/mesh/element_detail.h), the swatch it was
  // made from: its symmetry decides the method and the global layout's lattice, which the
  // simplified copies keep only approximately (no exact half turn), so that a Preview and the
  // full run are the same layout. Not owned; null: the swatch given decides.
  const TriMesh* full_detail_swatch = nullptr;
  // Local patches grow to this many times the swatch's footprint area (paper: "up to an area
  // threshold"); 0: a disk reaching the farthest swatch corner of any admissible placement. A
  // patch whose area distortion exceeds max_distortion is shrunk (paper: 4), judged by the 95th
  // percentile of its faces' distortion.
  double patch_area_factor = 0;
  double max_distortion = 4.0;
  double subpatch_fraction = 0.5;  // as for planar quilting
  // The base is refined until no edge is longer than this fraction of the swatch's longer side.
  double base_edge_fraction = 0.3;
  // Fewer sub-patch points and a coarser sub-cell refinement than on the plane: a conformal
  // patch is only accurate to a fraction of a cell anyway, and surfaces need many patches.
  int match_points = 512;
  MatchingOptions matching = [] {
    MatchingOptions m;
    m.refine_to = 1.0 / 16.0;
    return m;
  }();
  PatchQuiltingOptions patch;
  uint64_t seed = 1;
  // Refuse a job whose output is estimated above this many faces (the swatch's faces per unit
  // of footprint area times the base's area): issue 14.
  double max_faces = 2e7;
  // Turn base components whose faces point inward to face outward (orient_outward) first.
  bool orient_outward = true;
  // A base of more faces than this is simplified first (simplify_by_quadrics, issue 14): to
  // edges no longer than the refinement's (base_edge_fraction of the swatch's side), within
  // proxy_error shell heights of the surface given. The texture is then laid over that proxy.
  // 0: never.
  int proxy_min_faces = 200'000;
  double proxy_error = 0.05;
  // The global-parameterisation method (core/surface/global_quilting).
  struct Global {
    // Stop once the output's size is known (the lattice's copies counted, the vines' estimate,
    // the preparation's for the patches), placing nothing: `meshquilt surface --estimate`.
    bool count_only = false;
    // Weight of the guidance field against the line field's smoothness: small lets the
    // field's poles split into the mild half-turn cones a lattice can close around.
    double guidance_weight = 1e-3;
    // Weight of the one implicit Laplacian step that smooths the copy of the base the field and
    // the parameterisation are computed on (0: the base itself).
    double smoothing = 1.0;
    // Pin the cones and fix the transitions at the texture's symmetries (periodic swatches).
    bool seamless = true;
    // Cancel + and - cones at the two ends of one edge (cancel_singular_pairs).
    bool cancel_cone_pairs = true;
    // After the cones are moved, cancel + and - cone pairs while that raises the mean squared
    // log scale by at most this (ConePlacementOptions::pair_allowance); negative: none.
    double cone_pair_allowance = 0.01;
    // Move the cones for the least change of scale (core/surface/cone_placement) and lay the
    // texture out conformally, by the field parallel in their flat metric scaled by e^u
    // (core/surface/trivial_connection); false: unit frames of the smooth line field.
    bool conformal = true;
    // The metric's scale is followed as e^(a u) with a <= 1 such that the lattice, normalised
    // to the typical element's size, fills the surface at most this many times over
    // (e^(2 a^2 E), E the mean squared log scale after the cones are placed).
    double max_overfill = 1.2;
    // How a lattice element is carried onto the base: through the layout vertex by vertex
    // (kLayout: it keeps its place among its neighbours exactly, and takes the layout's
    // distortion across it); as a copy of the layout's first-order image at its centre whose
    // offsets are walked along the surface, a similarity (kRigid: bent by the surface only);
    // or through the layout where that keeps its shape and as a first-order copy elsewhere
    // (kAdaptive). The shape is kept when the layout there is nearly a similarity (aspect at
    // most max_element_aspect), the same one across the element (its halves' scales within
    // max_element_variation) and the element at most max_element_scale times the swatch's. A
    // copy's size is clamped to [1 / max_element_scale, max_element_scale] times the swatch's.
    enum class Placement { kLayout, kRigid, kAdaptive };
    Placement placement = Placement::kAdaptive;
    double max_element_scale = 1.3;
    double max_element_aspect = 1.3;
    double max_element_variation = 1.3;
    // An element the layout makes smaller than small_element_scale times the swatch's keeps the
    // layout's version at any variation across it and an aspect up to small_element_aspect. It
    // lies where the layout gathers curvature (around a positive cone), among neighbours as
    // small: an even copy of full size collides with them and is removed, and the ring lattice
    // loses its links there (bunny: 79 elements removed against 23, 92.0% of rings linked
    // against 94.3%). 0 turns the exception off.
    double small_element_scale = 0.95;
    double small_element_aspect = 2.0;
    // A periodic swatch of compact elements is tiled over the parameter plane (the planar
    // quilt it would give), one of threads by one-period pieces welded into threads
    // (core/surface/thread_tiling); else the plane is quilted.
    bool tile = true;
    // The quilt will be embedded by plain normal displacement: thread pieces that it folds
    // through themselves are left out (a folded thread would be removed whole). The shell map
    // unfolds them, so they are kept for it.
    bool drop_folded_pieces = false;
  } global;
};

struct SurfaceQuiltingStats {
  int iterations = 0;
  int base_faces = 0;          // after refinement
  int welded_vertices = 0;     // base vertices merged with another at the same position
  int duplicate_faces = 0;     // base faces that repeated another, removed
  int sheet_back_faces = 0;    // backs of a two-sided base (every face listed again facing the
                               // other way: nothing enclosed), removed
  int flipped_components = 0;  // base components turned to face outward (orient_outward)
  int fin_faces = 0;           // base faces in fins (core/mesh/fins.h), left out
  double fin_area_share = 0;   // their share of the base's area
  int non_manifold_edges = 0;  // of the base without its fins: borders for the texture
  int proxy_faces = 0;         // faces of the simplified base (0: the base was not simplified)
  double proxy_error = 0;      // the simplification's largest quadric error (mesh units)
  int patches_shrunk = 0;
  long long patch_faces = 0;  // faces of every local patch used (after shrinking), summed
  double swatch_scale = 0;    // factor applied to the swatch
  double shell_height = 0;
  double cell_size = 0;
  long long matched_point_offsets = 0;
  PatchCounts counts;
  int rejected_outside_patch = 0;             // swatch elements reaching beyond the flattened patch
  int faces = 0, vertices = 0, elements = 0;  // before the embedding's post-processing
  // Output faces estimated before any work (the swatch's faces per footprint area over the
  // base's area), and, for the global layout, counted once the layout is known.
  double estimated_faces = 0;
  StageTimes times;
};

// The base and the swatch as both surface methods work on them: the base with coincident
// vertices welded and refined, the guidance field on the refined faces (the smooth default when
// none is given), the swatch scaled to its size on the surface.
struct SurfaceJob {
  TriMesh cleaned;                // the base as given, coincident vertices welded (or its proxy)
  TriMesh base;                   // cleaned, refined by longest-edge bisection
  Refinement refinement;          // base faces in cleaned faces
  std::vector<int> input_vertex;  // #V(cleaned): its vertex in the base as given (empty: proxy)
  MatrixX3d field;                // #F(base) by 3 unit tangents
  EdgeTopology topo;
  MatrixX3i TT;
  double swatch_scale = 0;  // factor applied to the swatch
  TriMesh swatch;           // the swatch scaled by it
  TriMesh full_swatch;      // options.full_detail_swatch scaled by it (empty: none given)
  // Under a proxy: the base as given, welded, and its input_vertex (SurfaceQuilt::welded_base).
  TriMesh welded;
  std::vector<int> welded_input_vertex;
  // #V(base): log of options.size_map at each vertex (interpolated where the base was refined,
  // the mean over a proxy vertex's faces' input faces); empty without a size map.
  Eigen::VectorXd log_size;
};

// Moves the job's bases into the quilt: cleaned (input_base), refinement, input_vertex and,
// under a proxy, the welded base as given; sets SurfaceQuilt::sized.
void take_input_bases(SurfaceJob& job, SurfaceQuilt& quilt);

// The element size the size map asks for on face f of job.base, as a factor of job.swatch's
// (the geometric mean of its corners' SurfaceJob::log_size): in (0, 1]; 1 without a size map.
double nominal_size(const SurfaceJob& job, int f);
// Its log: the mean of the corners' SurfaceJob::log_size (0 without a size map).
double face_log_size(const SurfaceJob& job, int f);

// The swatch at full detail, which decides the method and the layout (a Preview is then the full
// run's layout, SurfaceQuiltingOptions::full_detail_swatch): job.full_swatch prepared into
// `storage` when one was given, else `swatch` (job.swatch prepared), which is at full detail.
const PreparedSwatch& swatch_at_full_detail(const SurfaceJob& job, const PreparedSwatch& swatch,
                                            PreparedSwatch& storage);

// The factor taking swatch units to base units for SurfaceQuiltingOptions::scale = `scale`: the
// swatch's longer side (of its prepared footprint) becomes `scale` times the base's bounding-box
// diagonal (section 3.1's relative size s). Throws InvalidInput for scale <= 0 or not finite, an
// empty base or swatch.
double swatch_scale_for(const TriMesh& base, const TriMesh& swatch, double scale);

// The swatch's longer footprint side (of its prepared footprint, swatch units): the element
// size is this times the swatch scale. Throws InvalidInput for an empty swatch.
double longer_footprint_side(const TriMesh& swatch);

// "--scale S" or "--element-size L", whichever sets the size in `options`: for messages.
std::string size_option(const SurfaceQuiltingOptions& options);

// Validates the inputs (the same throws as quilt_surface) and prepares a SurfaceJob; times go
// to the stage "prepare", welded vertices and base faces to stats.
SurfaceJob prepare_surface_job(const TriMesh& base, const TriMesh& swatch,
                               const SurfaceQuiltingOptions& options, SurfaceQuiltingStats& stats);

// Runs mesh quilting over `base`. Local coordinates in the result refer to the base (coincident
// vertices welded) refined by bisect_longest_edges(base, element size * base_edge_fraction,
// 2'000'000), the element size being element_size or else scale * diagonal;
// SurfaceQuilt::refinement maps them back. Throws InvalidInput for an empty or non-finite base or
// swatch, scale <= 0 or not finite, element_size < 0 or not finite, a field of the wrong size.
SurfaceQuilt quilt_surface(const TriMesh& base, const TriMesh& swatch,
                           const SurfaceQuiltingOptions& options,
                           TranslationCostEvaluator& evaluator,
                           SurfaceQuiltingStats* stats = nullptr, ProgressSink* progress = nullptr);

// quilt_surface on a job prepare_surface_job made with the same options (`stats`: the figures
// and times so far), for a caller that has prepared it already. Throws like quilt_surface.
SurfaceQuilt quilt_prepared_surface(SurfaceJob job, SurfaceQuiltingStats stats,
                                    const SurfaceQuiltingOptions& options,
                                    TranslationCostEvaluator& evaluator,
                                    SurfaceQuiltingStats* stats_out = nullptr,
                                    ProgressSink* progress = nullptr);

// 3D positions of local coordinates by plain normal displacement: the base point plus height
// times the interpolated unit vertex normal.
//   N  #V(base) by 3 unit vertex normals of the base
Vector3d displace_along_normal(const TriMesh& base, const MatrixX3d& N, int face,
                               const Vector3d& barycentric, double height);

// The whole quilt embedded by normal displacement over quilt.base, elements in order.
TriMesh embed_by_normal_displacement(const SurfaceQuilt& quilt);

}  // namespace mq
