// meshquilt info FILE: counts, bounding box and topology of a mesh.
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/json_writer.h"
#include "cli/run_context.h"
#include "cli/stats_json.h"
#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/structure/texture_structure.h"
#include "core/surface/surface_quilting.h"

namespace mq::cli {

namespace {

void declare_info_options(CommandLine& cl) {
  cl.positional("FILE", "mesh file to inspect");
  cl.flag("json", "print the same figures as JSON");
  cl.flag("intersections",
          "also count pairs of intersecting faces between different elements, and elements "
          "that intersect themselves");
  cl.flag("links", "measure links between rings, ends of long elements and density");
  cl.option("swatch", "FILE", "with --links: the swatch the mesh was made from");
  cl.option("base", "FILE",
            "with --links: the base mesh of a surface result (its area and boundary)");
  cl.option("scale", "S",
            "with --swatch and --base: the scale the result was quilted at, as surface --scale "
            "(default: estimated from the element sizes)");
  cl.option("elements", "CSV",
            "with --links: write one line per element to this CSV file: centre, size, area, ring, "
            "links, interior, long, length, interior ends, kind, defect (none, not_ring, no_hole, "
            "folded), loop links (degenerate rings' counted), wire and opening (diameters), fold "
            "(degrees), and with --swatch size ratio, aspect, stretch and by_correspondence (0 "
            "where not measured)");
}

// The mesh, refused when its coordinates are so large that finite differences overflow (they
// would print inf and nan sizes and areas).
TriMesh read_measurable_mesh(const std::string& path) {
  TriMesh mesh = read_mesh(path);
  MQ_CHECK(mesh.V.rows() == 0 || (bounding_box(mesh.V).extent().allFinite() &&
                                  (mesh.V.cwiseAbs().maxCoeff() < 1e150)),
           InvalidInput, path, ": coordinates too large to measure (up to ",
           mesh.V.cwiseAbs().maxCoeff(), "; sizes and areas would overflow)");
  return mesh;
}

// --links: the structure, with --swatch against the swatch's (at --scale when given), else
// with --base's border and area.
struct LinkFigures {
  StructureReport structure;
  std::optional<SwatchStructure> swatch;
  std::optional<StructureComparison> comparison;
};

LinkFigures measure_links(const TriMesh& mesh, const CommandLine& cl, double scale) {
  LinkFigures l;
  std::optional<TriMesh> base;
  if (cl.has("base")) base = read_mesh(cl.get("base"));
  if (cl.has("swatch")) {
    const TriMesh swatch_mesh = read_mesh(cl.get("swatch"));
    // Output units per swatch unit, as the surface command computed it.
    const double linear_scale = scale > 0 ? swatch_scale_for(*base, swatch_mesh, scale) : 0;
    const StructureSummary s =
        summarize_structure(mesh, swatch_mesh, base ? &*base : nullptr, linear_scale);
    l.structure = s.output;
    l.swatch = s.swatch;
    l.comparison = s.comparison;
    return l;
  }
  StructureOptions so;
  if (base) {
    so.automatic_border = false;
    so.border = mesh_border(base->V, base->F);
    so.area = surface_area(base->V, base->F);
  }
  l.structure = measure_structure(mesh, so);
  return l;
}

// --elements: one CSV line per element.
void write_elements_csv(const std::string& path, const StructureReport& structure) {
  std::string csv =
      "element,x,y,z,size,area,ring,links,interior,long,length,interior_ends,kind,defect,"
      "loop_links,wire,opening,fold_degrees,size_ratio,aspect,stretch,by_correspondence\n";
  char line[512];
  for (size_t k = 0; k < structure.elements.size(); ++k) {
    const ElementStructure& e = structure.elements[k];
    std::snprintf(line, sizeof line,
                  "%zu,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%d,%d,%.9g,%d,%s,%s,%d,%.9g,%.9g,%.6g,%.9g,"
                  "%.9g,%.9g,%d\n",
                  k, e.centre.x(), e.centre.y(), e.centre.z(), e.size, e.area, e.ring ? 1 : 0,
                  e.links, e.interior ? 1 : 0, e.long_element ? 1 : 0, e.length, e.interior_ends,
                  sanitized_kind(structure.kinds[static_cast<size_t>(e.kind)]).c_str(),
                  ring_defect_name(e.defect), e.loop_links, e.wire, e.opening, e.fold * 180 / M_PI,
                  e.size_ratio, e.aspect, e.stretch, e.by_correspondence ? 1 : 0);
    csv += line;
  }
  write_file_atomically(path, csv);
}

// The figures every info prints: topology, box, area, mean edge, the elements per kind (in
// the order the file names the kinds) and with --intersections the intersection counts.
struct MeshFigures {
  TopologyReport topo;
  BoundingBox box;
  Vector3d size;
  double area = 0, edge = 0;
  bool check = false;
  long long crossing = -1, self_crossing = -1;
  std::vector<std::pair<std::string, int>> per_kind;
};

MeshFigures mesh_figures(const TriMesh& mesh, bool check) {
  MeshFigures m;
  m.topo = topology_report(mesh);
  m.box = bounding_box(mesh.V, mesh.F);
  m.size = m.box.extent();
  m.area = surface_area(mesh.V, mesh.F);
  m.edge = mean_edge_length(mesh.V, mesh.F);
  m.check = check;
  if (check) {
    m.crossing = static_cast<long long>(intersecting_face_pairs(mesh.V, mesh.F).size());
    m.self_crossing = static_cast<long long>(self_intersecting_components(mesh.V, mesh.F).size());
  }
  if (has_kinds(mesh)) {
    const ElementLabels labels = element_labels(mesh);
    for (const std::string& k : labels.kinds) m.per_kind.emplace_back(k, 0);
    for (const int k : labels.element_kind) ++m.per_kind[static_cast<size_t>(k)].second;
  }
  return m;
}

void print_info_json(const std::string& path, const TriMesh& mesh, const MeshFigures& m,
                     const std::optional<LinkFigures>& links) {
  JsonWriter j;
  j.begin_object()
      .value("file", path)
      .value("faces", mesh.num_faces())
      .value("vertices", mesh.num_vertices())
      .value("elements", m.topo.num_components)
      .begin_object("kinds");
  for (const auto& [name, count] : m.per_kind) j.value(name, count);
  j.end_object().begin_array("bbox_min");
  for (int k = 0; k < 3; ++k) j.value("", m.box.min(k));
  j.end_array().begin_array("bbox_max");
  for (int k = 0; k < 3; ++k) j.value("", m.box.max(k));
  j.end_array()
      .value("thickness", m.size.minCoeff())
      .value("closed", m.topo.closed())
      .value("manifold", m.topo.manifold())
      .value("boundary_edges", m.topo.num_boundary_edges)
      .value("non_manifold_edges", m.topo.num_non_manifold_edges)
      .value("non_manifold_vertices", m.topo.num_non_manifold_vertices)
      .value("degenerate_faces", m.topo.num_degenerate_faces)
      .value("surface_area", m.area)
      .value("mean_edge_length", m.edge);
  if (m.check)
    j.value("intersecting_face_pairs", m.crossing)
        .value("self_intersecting_elements", m.self_crossing);
  if (links)
    write_structure(j, links->structure, links->swatch ? &*links->swatch : nullptr,
                    links->comparison ? &*links->comparison : nullptr);
  j.end_object();
  std::fputs(j.str().c_str(), stdout);
}

void print_info_text(const std::string& path, const TriMesh& mesh, const MeshFigures& m,
                     const std::optional<LinkFigures>& links) {
  std::printf("file:              %s\n", path.c_str());
  std::printf("faces:             %d\n", mesh.num_faces());
  std::printf("vertices:          %d\n", mesh.num_vertices());
  std::printf("elements:          %d\n", m.topo.num_components);
  if (!m.per_kind.empty()) {
    std::string text;
    for (const auto& [name, count] : m.per_kind)
      text += (text.empty() ? "" : ", ") + std::to_string(count) + " " + name;
    std::printf("kinds:             %s\n", text.c_str());
  }
  const BoundingBox& box = m.box;
  std::printf("bounding box:      [%.6g, %.6g, %.6g] - [%.6g, %.6g, %.6g]\n", box.min.x(),
              box.min.y(), box.min.z(), box.max.x(), box.max.y(), box.max.z());
  std::printf("size:              %.6g x %.6g x %.6g (thickness %.6g)\n", m.size.x(), m.size.y(),
              m.size.z(), m.size.minCoeff());
  std::printf("closed:            %s\n", m.topo.closed() ? "yes" : "no");
  std::printf("boundary edges:    %d\n", m.topo.num_boundary_edges);
  std::printf("non-manifold:      %d edges, %d vertices\n", m.topo.num_non_manifold_edges,
              m.topo.num_non_manifold_vertices);
  std::printf("degenerate faces:  %d\n", m.topo.num_degenerate_faces);
  std::printf("surface area:      %.6g\n", m.area);
  std::printf("mean edge length:  %.6g\n", m.edge);
  if (m.check) {
    std::printf("intersecting face pairs between elements: %lld\n", m.crossing);
    std::printf("self-intersecting elements: %lld\n", m.self_crossing);
  }
  if (links)
    print_structure(links->structure, links->swatch ? &*links->swatch : nullptr,
                    links->comparison ? &*links->comparison : nullptr);
}

}  // namespace

int run_info(int argc, char** argv, int first) {
  CommandLine cl(
      "info", "FILE [--json] [--intersections] [--links [--swatch SW] [--base BASE]]",
      "Prints the faces, vertices, geometry elements (connected components), bounding\n"
      "box, thickness (smallest box side), closedness and manifoldness of a mesh file\n"
      "(OBJ, PLY or OFF). --links measures the texture's structure: how many rings\n"
      "each ring-shaped element is interlinked with (linking number of centre loops),\n"
      "where long elements (threads, vines) end, and elements per unit area. A ring\n"
      "whose free hole is narrower than its wire (no hole), whose halves turn more than\n"
      "60 degrees against each other (folded), or of a ring kind but not ring-shaped is\n"
      "degenerate: a miss, linked to nothing. With --swatch, how that compares with the\n"
      "swatch's own structure: each ring against its own kind's interior link count, and\n"
      "the shape (size ratio, aspect) of compact elements against their swatch element.");
  declare_info_options(cl);
  if (!cl.parse(argc, argv, first)) return 0;
  const std::string path = cl.positional_value("FILE");
  const bool links = cl.has("links");
  if (!links && (cl.has("swatch") || cl.has("base") || cl.has("scale") || cl.has("elements")))
    throw UsageError("--swatch, --base, --scale and --elements need --links");
  if (cl.has("scale") && !(cl.has("swatch") && cl.has("base")))
    throw UsageError("--scale needs --swatch and --base (it is relative to the base's size)");
  const double scale = cl.has("scale") ? cl.get_double("scale", 0, 1e-12, 1e12) : 0;
  check_paths({cl.get("elements")}, {path, cl.get("swatch"), cl.get("base")});
  const TriMesh mesh = read_measurable_mesh(path);
  std::optional<LinkFigures> link_figures;
  if (links) link_figures = measure_links(mesh, cl, scale);
  if (links && cl.has("elements")) write_elements_csv(cl.get("elements"), link_figures->structure);
  const MeshFigures figures = mesh_figures(mesh, cl.has("intersections"));
  if (cl.has("json"))
    print_info_json(path, mesh, figures, link_figures);
  else
    print_info_text(path, mesh, figures, link_figures);
  return 0;
}

}  // namespace mq::cli
