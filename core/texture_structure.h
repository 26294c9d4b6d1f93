// The structure a quilt must keep from its swatch (paper section 1.2: "maintain the integrity of
// these geometry elements"), measured per element: which ring-shaped elements are interlinked
// (chain mail), where long elements (threads, vines) end, and how densely elements are packed.
// These figures judge a result where aggregate ones (faces, coverage) cannot: a quilt of
// closed, disjoint but unlinked rings has every aggregate right and is not chain mail.
#pragma once

#include <functional>
#include <vector>

#include "core/linking_number.h"
#include "core/mesh.h"

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

struct StructureOptions {
  // Automatic: Kind::FlatBox when the element centres lie in one plane (within half the median
  // element size), else Kind::None. Give mesh_border(base) for a surface result.
  bool automatic_border = true;
  TextureBorder border;
  // Elements whose centre lies closer than this to the border are border elements (their
  // neighbours beyond the border are missing by construction); 0: the median element size plus
  // the median spacing (elements on a base must lie wholly on it, so the outermost centres
  // can lie that far inside its edge).
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
};

// One element of the measured mesh.
struct ElementStructure {
  Vector3d centre = Vector3d::Zero();  // mean vertex
  double size = 0;                     // twice the largest distance from the centre to a vertex
  double area = 0;                     // surface area of the element
  bool ring = false;                   // closed genus-1 and surrounds its centre (has a loop)
  int links = 0;                       // rings it is interlinked with (|linking number| >= 1)
  bool interior = true;                // farther than interior_margin from the border
  bool long_element = false;           // a thread or vine: length >= 4 times its width
  double length = 0, width = 0;        // long elements: end-to-end length along the surface
  int interior_ends = 0;               // of its two ends, those away from the border
};

struct StructureReport {
  std::vector<ElementStructure> elements;
  std::vector<std::pair<int, int>> linked_pairs;  // (i, j), i < j, ascending
  TextureBorder::Kind border = TextureBorder::Kind::None;
  double median_size = 0;
  double median_area = 0;     // of the elements' surface areas
  double median_spacing = 0;  // median distance from an element centre to the nearest other
  int rings = 0, interior_rings = 0, isolated_rings = 0;  // isolated: no link at all
  // [k]: interior rings interlinked with exactly k others.
  std::vector<int> interior_link_histogram;
  std::vector<int> link_histogram;  // the same over all rings
  int long_elements = 0, ends = 0, interior_ends = 0;
  double area = 0;  // 0: unknown
  // Elements per unit area: interior elements over the total area of their Voronoi cells in
  // the tangent plane at each (neighbours within 4 spacings projected), counting the cells
  // that neighbours close on every side. A hole in the texture enlarges the cells around it;
  // a perfect lattice gives exactly its density. 0: no cell closes.
  double density = 0;
  int density_cells = 0;  // the closed cells it was measured on
  double interior_ends_per_area = 0;
  // Share of interior rings with exactly k links (0 when there are none).
  double share_with_links(int k) const;
};

// Measures the structure of a mesh whose connected components are the elements.
// Throws InvalidInput for non-finite coordinates or out-of-range indices.
StructureReport measure_structure(const TriMesh& mesh, const StructureOptions& options = {});

// The swatch's own structure, the reference an output is judged against.
struct SwatchStructure {
  StructureReport report;  // measured in the swatch's plane (thickness axis removed)
  // The link count of an interior ring: the largest count held by at least a tenth of the
  // swatch's rings (a sheet's border rings have fewer; -1 without rings).
  int interior_links = -1;
  // Elements per unit area inside the swatch: the mean area of the Voronoi cells (in the
  // swatch plane) of element centres whose cell closes inside the centres' box; when no cell
  // does (a sheet two elements wide), 1 / the median area of the parallelogram spanned by a
  // centre's nearest and nearest non-parallel neighbours (exact for a lattice).
  double density = 0;
};

// Measures a swatch (any orientation: its smallest bounding-box side is the thickness).
// Throws InvalidInput like measure_structure, and for a swatch prepare_swatch rejects.
SwatchStructure measure_swatch_structure(const TriMesh& swatch);

// How an output compares with its swatch, scale taken into account.
struct StructureComparison {
  int interior_links = -1;    // the swatch's
  double share_matching = 0;  // interior output rings with exactly that many links
  // Output density / swatch density at the output's scale; 0 when most swatch elements are long
  // (threads join across seams, so their count per area says nothing; see interior ends).
  double density_ratio = 0;
  double linear_scale = 0;    // output length units per swatch unit
  // Distortion of compact elements (rings, apples; not threads or vines, which seams cut):
  // sizes (ElementStructure::size) over the swatch's median size at the output's scale. The
  // map stretches an element where it is as wide as the feature under it (a spike, a hoof).
  // 0 when most swatch elements are long.
  int stretched = 0;        // compact output elements over kStretchedSize times that size
  double largest_size = 0;  // the largest such ratio
  static constexpr double kStretchedSize = 1.5;
};

// linear_scale: output length per swatch length; 0 estimates it from the median element
// surface areas (their square root; a size along one direction would follow the stretch of
// curved bases), so give it when known.
StructureComparison compare_structure(const StructureReport& output, const SwatchStructure& swatch,
                                      double linear_scale = 0);

// The figures of an output against its swatch in one call: measured with the base's boundary,
// area and normals when a base is given (a surface result), else as a flat layer; compared at
// linear_scale (0: estimated).
struct StructureSummary {
  StructureReport output;
  SwatchStructure swatch;
  StructureComparison comparison;
};
StructureSummary summarize_structure(const TriMesh& output, const TriMesh& swatch,
                                     const TriMesh* base = nullptr, double linear_scale = 0);

}  // namespace mq
