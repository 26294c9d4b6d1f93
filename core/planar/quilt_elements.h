// Geometry elements (connected components, paper section 2.1) as the unit the quilting steps
// move, deform, cut and stitch, and the swatch put in its synthesis frame.
#pragma once

#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// One geometry element: its own vertices and faces plus cached normals and footprint.
struct Element {
  MatrixX3d V;  // #V by 3
  MatrixX3i F;  // #F by 3
  MatrixX3d N;  // #V by 3 unit vertex normals (kept in sync by update())
  Vector2d lo = Vector2d::Zero(), hi = Vector2d::Zero();  // xy footprint bounding box
  double z_lo = 0, z_hi = 0;
  int kind = 0;  // index into the swatch's kinds (PreparedSwatch::kinds); copies keep it
  // Optional (issue 25, swatch animation): where each vertex comes from, a point of the prepared
  // swatch's element source_element[v] in its synthesis frame (#V by 3 and #V, or both empty:
  // not tracked). track_sources sets them on the swatch; copies keep them, element_part and the
  // stitch (section 2.7) carry them vertex for vertex, and deformations leave them as they are.
  MatrixX3d source;
  std::vector<int> source_element;

  // Recomputes normals and bounds after V changed.
  void update();
  // Translates by t, keeping normals.
  void translate(const Vector3d& t);
  double footprint_diameter() const { return (hi - lo).norm(); }
  // A footprint at least 4 times longer than wide: a thread or a vine, or a piece of one.
  bool long_footprint() const {
    const Vector2d side = hi - lo;
    return side.maxCoeff() >= 4 * side.minCoeff();
  }
  // The element as a plain mesh (V and F copied, no normals).
  TriMesh mesh() const {
    TriMesh m;
    m.V = V;
    m.F = F;
    return m;
  }
};

// Splits a mesh into elements, in order of each component's first face. An element's kind is
// the one most of its faces have in mesh (component_kinds), 0 when mesh has no kinds.
std::vector<Element> split_elements(const TriMesh& mesh);

// The faces `faces` of e (indices into e.F) as an element of its own, vertices numbered by first
// use, sources carried (Element::source), normals and bounds updated.
Element element_part(const Element& e, const std::vector<int>& faces);

// One part of an element made of others: the vertices of `from` it takes, in its order.
struct SourcePart {
  const Element* from = nullptr;
  const std::vector<int>* vertices = nullptr;
};

// Sets to's sources (Element::source) to those of the parts' vertices, part after part; none
// when some part has none.
void carry_sources(const std::vector<SourcePart>& parts, Element& to);

// Concatenates elements into one mesh (in order). face_kind holds each face's element kind;
// kinds is left empty for the caller to name (PreparedSwatch::kinds).
TriMesh merge_elements(const std::vector<const Element*>& elements);

// The swatch in its synthesis frame: thickness axis (smallest bounding-box side) along z and
// bounding-box minimum at the origin, so its footprint is [0, size.x] x [0, size.y].
struct PreparedSwatch {
  std::vector<Element> elements;
  TriMesh mesh;                   // all elements, same vertex order as the elements concatenated
  std::vector<int> face_element;  // #F: element of each face of mesh
  std::vector<int> element_first_face;  // first face of each element in mesh
  std::vector<int> element_first_vertex;
  std::vector<std::string> kinds;  // names of Element::kind: the swatch's, or {kDefaultKind}
  Vector3d size = Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // input frame -> synthesis frame
  Vector3d translation = Vector3d::Zero();                 // applied after rotation
  double mean_edge_length = 0;
  double mean_element_diameter = 0;  // mean footprint diameter of the elements
};

// Validates and prepares a swatch. Throws InvalidInput for an empty mesh, non-finite
// coordinates, out-of-range indices, or a swatch whose footprint has zero area.
PreparedSwatch prepare_swatch(const TriMesh& swatch);

// Makes every swatch element its own source (Element::source: its vertices, element i), so that
// the copies a quilt is made of say where each of their vertices comes from.
void track_sources(PreparedSwatch& swatch);

}  // namespace mq
