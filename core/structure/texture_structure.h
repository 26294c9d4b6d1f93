// The structure a quilt must keep from its swatch (paper section 1.2: "maintain the integrity of
// these geometry elements"), measured per element: which ring-shaped elements are interlinked
// (chain mail), where long elements (threads, vines) end, and how densely elements are packed.
// These figures judge a result where aggregate ones (faces, coverage) cannot: a quilt of
// closed, disjoint but unlinked rings has every aggregate right and is not chain mail.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/mesh/linking_number.h"
#include "core/mesh/mesh.h"

namespace mq {

// Where the texture's domain ends, for telling border elements from interior ones.
struct TextureBorder {
  enum class Kind {
    None,      // a closed surface: every element is interior
    Segments,  // the given polyline segments (a base mesh's boundary edges)
    FlatBox,   // a flat layer: the box of the element centres in their common plane
  };
  Kind kind = Kind::None;
  std::vector<std::pair<Vector3d, Vector3d>> segments;  // Kind::Segments
};

// The boundary edges of a base mesh as a border (Kind::None for a closed base).
//   V  #V by 3, F  #F by 3
TextureBorder mesh_border(const MatrixX3d& V, const MatrixX3i& F);

struct SwatchStructure;

struct StructureOptions {
  // Automatic: Kind::FlatBox when the element centres lie in one plane (within half the median
  // element size), else Kind::None. Give mesh_border(base) for a surface result.
  bool automatic_border = true;
  TextureBorder border;
  // Elements whose centre lies closer than this to the border are border elements (their
  // neighbours beyond the border are missing by construction); 0: the median element size (of
  // the kind whose elements are largest, among those with a tenth of the elements) plus the
  // median spacing (elements on a base must lie wholly on it, so the outermost centres can lie
  // that far inside its edge).
  double interior_margin = 0;
  // Ends of long elements closer than this to the border are where the texture stops, not
  // breaks; 0: 5 times the median width of the long elements (1.5 thread spacings on the
  // sample weave).
  double end_margin = 0;
  // Area of the textured domain, for ends per unit area; 0: estimated for a flat layer (the
  // centres' box grown by the median nearest-centre distance), unknown otherwise.
  double area = 0;
  // Unit normal of the surface under a point, for the tangent planes of the density measure;
  // empty: the normal of the plane best fitting the element's neighbour centres. When given,
  // neighbours whose surface faces another way (the other side of a cup's wall, of an ear)
  // are no neighbours.
  std::function<Vector3d(const Vector3d&)> surface_normal;
  int loop_bins = 32;  // points per ring centre loop
  // The swatch the mesh was made from (measure_swatch_structure's), or nullptr. With it, each
  // element is matched to a swatch kind (SwatchKind), a ring is judged folded against the
  // swatch's rings of its kind, the kinds whose swatch elements are rings decide which
  // elements are rings, and compact elements get shape figures. Without it, a ring is judged
  // folded against a flat ring and the mesh's own kinds decide (a kind is a ring kind when most
  // of its elements are ring-shaped).
  const SwatchStructure* swatch = nullptr;
  // With swatch: output length per swatch length, for the shape figures; 0: estimated from the
  // median element areas (their square root), or for a swatch mostly of long elements from
  // their median widths (the areas of welded threads follow their lengths, not the scale).
  double linear_scale = 0;
  // Rings judged folded (off only for the swatch itself, whose rings are the reference).
  bool judge_folds = true;

  // Throws InvalidInput when loop_bins < 8 or a margin, the area or the scale is negative or
  // not finite (0 is automatic).
  void validate() const;
};

// Why a ring cannot count as linked (issue 23: the measure counted rings squeezed shut or folded
// over a crease as linked). A degenerate ring is a miss in every link figure and links no ring:
// a link through a hole that no wire can pass, or through a ring that no longer lies like one,
// is the centre loop's artefact, not chain mail. Decided in this order, one cause per ring.
enum class RingDefect {
  None = 0,
  // Of a ring kind but not ring-shaped: open, not of genus 1, or not surrounding its centre
  // (torn, merged or melted), so it has no centre loop at all.
  NotRing,
  // Its free hole (RingShape::opening) is narrower than a wire: its own (RingShape::wire) or
  // the median one of the mesh's rings of its kind, whichever is thicker. No partner wire of
  // that gauge passes through it without intersecting it.
  NoHole,
  // Its halves turn more than kFoldLimit against each other beyond what its swatch ring's do
  // (RingShape::fold): their planes meet at under 120 degrees, so it is bent over an edge rather
  // than along the surface's curvature. Measured on tori of wire 0.15 radii: over a rounded
  // right-angled edge through its middle 75 degrees, half of it over that edge 61; on
  // cylinders of 1, 2 and 10 ring radii (wrapped round 115, 57 and 11 degrees of them) 58, 29
  // and 6.
  Folded,
};
constexpr int kRingDefects = 4;
constexpr double kFoldLimit = M_PI / 3;
// "none", "not_ring", "no_hole", "folded".
const char* ring_defect_name(RingDefect defect);

// One element of the measured mesh.
struct ElementStructure {
  Vector3d centre = Vector3d::Zero();  // mean vertex
  double size = 0;                     // twice the largest distance from the centre to a vertex
  double area = 0;                     // surface area of the element
  int kind = 0;                        // index into StructureReport::kinds
  int vertices = 0;                    // vertices its faces use
  // A ring: ring-shaped (closed genus 1 and surrounds its centre: has a centre loop), or of a
  // ring kind (then defect NotRing when it is not ring-shaped).
  bool ring = false;
  bool ring_shaped = false;
  RingDefect defect = RingDefect::None;  // rings
  bool degenerate() const { return defect != RingDefect::None; }
  // Rings it is interlinked with (|linking number| >= 1), neither degenerate; 0 when degenerate.
  int links = 0;
  // Centre loops interlinked with its own, degenerate rings' included (the count before
  // issue 23); ring-shaped elements only.
  int loop_links = 0;
  double wire = 0, opening = 0, fold = 0;  // ring-shaped elements: RingShape
  bool interior = true;                    // farther than interior_margin from the border
  bool long_element = false;               // a thread or vine: length >= 4 times its width
  // A long element closed on itself (a thread round a cup's body or handle: closed, genus 1,
  // ring-shaped or long, and of a long kind), with no ends. Not a ring.
  bool closed = false;
  // Long elements: end-to-end length along the surface (closed: the length of the loop round);
  // width: the diameter of a tube of that length and the element's area.
  double length = 0, width = 0;
  int interior_ends = 0;  // of its two ends, those away from the border
  // Measured against options.swatch: the swatch kind it was matched to (-1: none) and, for a
  // compact element (its swatch kind's elements mostly not long), its shape against the swatch
  // element it came from at the output's scale (0: not measured). The element's linear map from
  // that swatch element, restricted to the swatch element's plane of largest extent (the first
  // two principal axes of its vertices), has singular values t1 >= t2 (output per swatch length,
  // divided by the linear scale): size_ratio = sqrt(t1 t2) (its size, area-wise), aspect =
  // t1 / t2 (how unevenly it is stretched; 1 for a similar copy), stretch = t1 (its largest
  // stretch along any direction). The map is the best affine fit of its vertices to the swatch
  // element's (by_correspondence) when it has the same number of vertices as a swatch element of
  // its kind (a copy; of several differing ones, the one a similarity fits best) and the fit
  // leaves under half its spread; otherwise the principal extents s1 >= s2 of its vertices
  // against the median ones of its swatch kind: size_ratio = sqrt(s1 s2 / (r1 r2)), aspect the
  // ratio of s1 / s2 and r1 / r2 taken >= 1, stretch = size_ratio sqrt(aspect).
  int swatch_kind = -1;
  double size_ratio = 0, aspect = 0, stretch = 0;
  bool by_correspondence = false;
};

struct StructureReport {
  std::vector<ElementStructure> elements;
  std::vector<std::string> kinds;  // the mesh's kind names, or {kDefaultKind}
  // (i, j), i < j, ascending: interlinked rings, neither degenerate.
  std::vector<std::pair<int, int>> linked_pairs;
  int loop_linked_pairs = 0;  // interlinked centre loops, degenerate rings' included
  TextureBorder::Kind border = TextureBorder::Kind::None;
  double median_size = 0;
  double median_area = 0;     // of the elements' surface areas
  double median_spacing = 0;  // median distance from an element centre to the nearest other
  // isolated: rings with no link (degenerate ones included: they link nothing).
  int rings = 0, interior_rings = 0, isolated_rings = 0;
  // Rings by RingDefect (index 0: not degenerate), over all and over the interior ones.
  std::array<int, kRingDefects> defects{}, interior_defects{};
  int degenerate_rings() const { return rings - defects[0]; }
  int interior_degenerate() const { return interior_rings - interior_defects[0]; }
  // [k]: interior rings, not degenerate, interlinked with exactly k others (the degenerate
  // ones are in interior_defects).
  std::vector<int> interior_link_histogram;
  std::vector<int> link_histogram;  // the same over all rings
  int long_elements = 0, ends = 0, interior_ends = 0;
  int closed_long_elements = 0;  // of the long elements, closed on themselves (no ends)
  // The long elements' lengths (ElementStructure::length): their median and their sum; their
  // median width; and the elements that are not long (leaves along vines; rings), for their
  // count per length.
  double median_long_length = 0, long_length = 0, median_long_width = 0;
  int compact_elements = 0;
  double area = 0;  // 0: unknown
  // Elements per unit area: interior elements over the total area of their Voronoi cells in
  // the tangent plane at each (neighbours within 4 spacings projected), counting the cells
  // that neighbours close on every side. A hole in the texture enlarges the cells around it;
  // a perfect lattice gives exactly its density. 0: no cell closes.
  double density = 0;
  int density_cells = 0;  // the closed cells it was measured on
  double interior_ends_per_area = 0;
  // The scale the shape figures were measured at (0: no swatch given).
  double linear_scale = 0;
  // Share of interior rings with exactly k links, degenerate ones counting as misses (0 when
  // there are none).
  double share_with_links(int k) const;
};

// Measures the structure of a mesh whose connected components are the elements. Deterministic
// whatever the thread count. O(#F log #F) plus, per pair of rings whose loops' boxes overlap,
// O(#loop^2).
// Throws InvalidInput for non-finite coordinates, out-of-range indices, invalid kinds or
// options that StructureOptions::validate rejects.
StructureReport measure_structure(const TriMesh& mesh, const StructureOptions& options = {});

// One kind of swatch element, the reference its output elements are judged against.
struct SwatchKind {
  std::string name;
  int elements = 0, rings = 0, long_elements = 0;  // rings: ring-shaped elements
  bool ring = false;     // most of its elements are ring-shaped: a ring kind
  bool compact = false;  // most of its elements are not long (rings, apples, leaves)
  // Ring kinds: the link count of an interior ring of this kind: the largest count held by at
  // least a tenth of its rings (a sheet's border rings have fewer; -1 without rings).
  int interior_links = -1;
  double fold = 0;                      // median RingShape::fold of its rings
  Vector3d extents = Vector3d::Zero();  // median principal extents (std. deviations, descending)
  // The distinct shapes among its elements (up to a similarity, at most 16 per vertex count):
  // vertices minus their mean (#V by 3, in the order extract_faces gives an element of the
  // swatch), and the first two principal axes (3 by 2).
  struct Shape {
    MatrixX3d V;
    Eigen::Matrix<double, 3, 2> axes;
  };
  std::vector<Shape> shapes;
};

// The swatch's own structure, the reference an output is judged against.
struct SwatchStructure {
  StructureReport report;  // measured in the swatch's plane (thickness axis removed)
  // The link count of an interior ring over all kinds: the largest count held by at least a
  // tenth of the swatch's rings (-1 without rings); SwatchKind has it per kind.
  int interior_links = -1;
  std::vector<SwatchKind> kinds;  // indexed like report.kinds
  // Elements per unit area inside the swatch: the mean area of the Voronoi cells (in the
  // swatch plane) of element centres whose cell closes inside the centres' box; when no cell
  // does (a sheet two elements wide), 1 / the median area of the parallelogram spanned by a
  // centre's nearest and nearest non-parallel neighbours (exact for a lattice).
  double density = 0;
  int ring_kinds() const;
};

// Measures a swatch (any orientation: its smallest bounding-box side is the thickness).
// Throws InvalidInput like measure_structure, and for a swatch prepare_swatch rejects.
SwatchStructure measure_swatch_structure(const TriMesh& swatch);

// The swatch kind an output element is judged against: the kind of the same name; else one
// whose elements have the same number of vertices (a copy; of several such kinds, the one with
// a shape a similarity takes best onto `positions` when given, #vertices by 3); else, for a
// ring, the ring kind with most rings, for another element the kind with most elements (-1 for
// an empty swatch).
int swatch_kind_for(const SwatchStructure& swatch, const std::string& kind, int vertices, bool ring,
                    const MatrixX3d* positions = nullptr);

// Links of the output's interior rings judged against one swatch ring kind.
struct KindComparison {
  std::string kind;         // the swatch kind's name
  int interior_links = -1;  // its interior rings' link count in the swatch
  int interior_rings = 0;   // output interior rings judged against it
  int matching = 0;         // of them, not degenerate and with exactly interior_links links
  int degenerate = 0;       // of them, degenerate
  double share = 0;         // matching / interior_rings (0 when none)
};

// Percentiles (nearest rank) of the compact elements' shape figures.
struct ShapeSummary {
  int elements = 0;           // compact elements measured
  int by_correspondence = 0;  // of them, by the affine fit to their swatch element
  double size_median = 0, size_p90 = 0, size_p99 = 0, size_max = 0;
  double aspect_median = 0, aspect_p90 = 0, aspect_max = 0;
};

// How an output compares with its swatch, scale taken into account.
struct StructureComparison {
  int interior_links = -1;  // the swatch's, over all kinds
  // Interior output rings whose link count is their own swatch kind's (each output ring judged
  // against the swatch kind swatch_kind_for gives; a kind without a count of its own takes the
  // swatch's over all kinds); degenerate rings are misses.
  double share_matching = 0;
  // The same share counting every interlinked centre loop and no ring degenerate: what the
  // measure said before issue 23, for comparison.
  double share_counting_degenerate = 0;
  std::vector<KindComparison> kinds;  // per swatch kind that judged an interior ring, in order
  // Output density / swatch density at the output's scale; 0 when most swatch elements are long
  // (threads join across seams, so their count per area says nothing; see interior ends).
  double density_ratio = 0;
  // Output length units per swatch unit: given, else the shapes' (StructureReport::
  // linear_scale), else from the median element areas.
  double linear_scale = 0;
  // Long elements (threads, vines): the output's median length in swatch long elements (its
  // median length over the swatch's at the output's scale: how many swatch threads a thread
  // runs, 1 for vines in swatch-sized pieces); its compact elements per long length against the
  // swatch's (1: leaves at the swatch's leaves per vine length); and its interior ends per unit
  // area at the swatch's scale (per swatch unit squared, comparable with a plane quilted from
  // the swatch). 0 when either has no long elements or the area is unknown.
  double long_length_ratio = 0, compact_per_length_ratio = 0;
  double interior_ends_per_swatch_area = 0;
  // The shape figures (ElementStructure::size_ratio, aspect) of compact elements (rings,
  // apples; not threads or vines, which seams cut); empty unless the output was measured with
  // the swatch. The map stretches an element where it is as wide as the feature under it (a
  // spike, a hoof).
  ShapeSummary shape;
  int stretched = 0;  // compact elements stretched over kStretchedSize along some direction
  double largest_stretch = 0;  // their largest ElementStructure::stretch
  static constexpr double kStretchedSize = 1.5;
};

// linear_scale: output length per swatch length, for the density; 0 takes output.linear_scale
// (the shapes' scale) or else estimates it from the median element surface areas (their square
// root; a size along one direction would follow the stretch of curved bases), so give it when
// known. Kinds are matched by swatch_kind_for unless the output was measured with the swatch.
StructureComparison compare_structure(const StructureReport& output, const SwatchStructure& swatch,
                                      double linear_scale = 0);

// The figures of an output against its swatch in one call: measured with the swatch (kinds,
// folds, shapes) and with the base's boundary, area and normals when a base is given (a surface
// result), else as a flat layer; compared at linear_scale (0: estimated).
struct StructureSummary {
  StructureReport output;
  SwatchStructure swatch;
  StructureComparison comparison;
};
StructureSummary summarize_structure(const TriMesh& output, const TriMesh& swatch,
                                     const TriMesh* base = nullptr, double linear_scale = 0);

}  // namespace mq
