#include "core/planar/quilt_elements.h"

#include <algorithm>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

void Element::update() {
  N = vertex_normals(V, F);
  if (V.rows() == 0) return;
  lo = V.leftCols<2>().colwise().minCoeff().transpose();
  hi = V.leftCols<2>().colwise().maxCoeff().transpose();
  z_lo = V.col(2).minCoeff();
  z_hi = V.col(2).maxCoeff();
}

void Element::translate(const Vector3d& t) {
  V.rowwise() += t.transpose();
  lo += t.head<2>();
  hi += t.head<2>();
  z_lo += t.z();
  z_hi += t.z();
}

std::vector<Element> split_elements(const TriMesh& mesh) {
  std::vector<int> fc;
  const int n = connected_components(mesh.F, mesh.num_vertices(), fc);
  const auto groups = component_faces(fc, n);
  const std::vector<int> kinds = component_kinds(mesh, fc, n);
  std::vector<Element> elements(n);
  for (int c = 0; c < n; ++c) {
    elements[c].kind = kinds[static_cast<size_t>(c)];
    const TriMesh part = extract_faces(mesh, groups[c]);
    elements[c].V = part.V;
    elements[c].F = part.F;
    elements[c].update();
  }
  return elements;
}

Element element_part(const Element& e, const std::vector<int>& faces) {
  std::vector<int> vertices;
  const TriMesh part = extract_faces(e.mesh(), faces, &vertices);
  Element out;
  out.V = part.V;
  out.F = part.F;
  out.kind = e.kind;
  carry_sources({{&e, &vertices}}, out);
  out.update();
  return out;
}

void carry_sources(const std::vector<SourcePart>& parts, Element& to) {
  to.source.resize(0, 3);
  to.source_element.clear();
  size_t n = 0;
  for (const SourcePart& p : parts) {
    if (p.from->source.rows() != p.from->V.rows() ||
        p.from->source_element.size() != static_cast<size_t>(p.from->V.rows()))
      return;
    n += p.vertices->size();
  }
  to.source.resize(static_cast<Eigen::Index>(n), 3);
  to.source_element.reserve(n);
  Eigen::Index row = 0;
  for (const SourcePart& p : parts)
    for (const int v : *p.vertices) {
      to.source.row(row++) = p.from->source.row(v);
      to.source_element.push_back(p.from->source_element[static_cast<size_t>(v)]);
    }
}

TriMesh merge_elements(const std::vector<const Element*>& elements) {
  Eigen::Index nv = 0, nf = 0;
  for (const Element* e : elements) {
    nv += e->V.rows();
    nf += e->F.rows();
  }
  TriMesh out;
  out.V.resize(nv, 3);
  out.F.resize(nf, 3);
  out.N.resize(nv, 3);
  out.face_kind.reserve(static_cast<size_t>(nf));
  nv = nf = 0;
  for (const Element* e : elements) {
    out.face_kind.insert(out.face_kind.end(), static_cast<size_t>(e->F.rows()), e->kind);
    out.V.middleRows(nv, e->V.rows()) = e->V;
    out.N.middleRows(nv, e->V.rows()) = e->N;
    out.F.middleRows(nf, e->F.rows()) = e->F.array() + static_cast<int>(nv);
    nv += e->V.rows();
    nf += e->F.rows();
  }
  return out;
}

PreparedSwatch prepare_swatch(const TriMesh& swatch) {
  MQ_CHECK(swatch.F.rows() > 0, InvalidInput, "the swatch has no faces");
  MQ_CHECK(swatch.V.allFinite(), InvalidInput, "the swatch has non-finite vertex coordinates");
  for (int f = 0; f < swatch.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(swatch.F(f, k) >= 0 && swatch.F(f, k) < swatch.V.rows(), InvalidInput,
               "swatch face ", f, " references missing vertex ", swatch.F(f, k));
  TriMesh m = swatch;
  remove_unreferenced_vertices(m);
  PreparedSwatch s;
  // Thickness axis (smallest side) becomes z; the other two keep their order (a cyclic
  // permutation, so orientation is preserved).
  const BoundingBox box0 = bounding_box(m.V);
  const Vector3d ext = box0.extent();
  int thin = 2;
  if (ext.x() < ext(thin)) thin = 0;
  if (ext.y() < ext(thin)) thin = 1;
  const int ax = (thin + 1) % 3, ay = (thin + 2) % 3;
  s.rotation.setZero();
  s.rotation(0, ax) = 1;
  s.rotation(1, ay) = 1;
  s.rotation(2, thin) = 1;
  m.V = (m.V * s.rotation.transpose()).eval();
  const BoundingBox box = bounding_box(m.V);
  s.translation = -box.min;
  m.V.rowwise() += s.translation.transpose();
  s.size = box.extent();
  MQ_CHECK(s.size.x() > 0 && s.size.y() > 0, InvalidInput,
           "the swatch's footprint has zero area (all vertices on a line)");
  // Sizes whose squares (areas, distances) underflow or overflow a double: a denormal swatch
  // was reported as non-finite further on (issue 14). Any real unit, micrometres to
  // kilometres, is far inside.
  MQ_CHECK(std::min(s.size.x(), s.size.y()) > 1e-100 && s.size.maxCoeff() < 1e100, InvalidInput,
           "the swatch's size (", s.size.x(), " x ", s.size.y(), " x ", s.size.z(),
           ") is too small or too large to compute with; rescale it");
  ensure_kinds(m);
  s.kinds = m.kinds;
  s.elements = split_elements(m);
  s.mean_edge_length = mean_edge_length(m.V, m.F);
  double diameter = 0;
  for (const Element& e : s.elements) diameter += e.footprint_diameter();
  s.mean_element_diameter = diameter / static_cast<double>(s.elements.size());
  std::vector<const Element*> ptrs;
  for (const Element& e : s.elements) ptrs.push_back(&e);
  s.mesh = merge_elements(ptrs);
  s.mesh.kinds = s.kinds;
  int f0 = 0, v0 = 0;
  for (size_t e = 0; e < s.elements.size(); ++e) {
    s.element_first_face.push_back(f0);
    s.element_first_vertex.push_back(v0);
    for (int k = 0; k < s.elements[e].F.rows(); ++k) s.face_element.push_back(static_cast<int>(e));
    f0 += static_cast<int>(s.elements[e].F.rows());
    v0 += static_cast<int>(s.elements[e].V.rows());
  }
  return s;
}

void track_sources(PreparedSwatch& swatch) {
  for (size_t i = 0; i < swatch.elements.size(); ++i) {
    Element& e = swatch.elements[i];
    e.source = e.V;
    e.source_element.assign(static_cast<size_t>(e.V.rows()), static_cast<int>(i));
  }
}

}  // namespace mq
