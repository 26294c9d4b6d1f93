// meshquilt render MESH -o PNG: a preview picture by Embree ray casting.
#include <algorithm>
#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/run_context.h"
#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/output/render.h"
#include "core/structure/texture_structure.h"
#include "core/surface/surface_quilting.h"

namespace mq::cli {

namespace {

using Rgb = std::array<unsigned char, 3>;
const Rgb kRed{{220, 40, 40}}, kOrange{{240, 140, 30}}, kYellow{{225, 205, 40}},
    kCyan{{60, 200, 220}}, kGreen{{40, 170, 60}}, kBlue{{50, 80, 220}}, kGrey{{150, 150, 150}},
    kMagenta{{200, 50, 200}};

void declare_render_options(CommandLine& cl) {
  cl.positional("MESH", "mesh file (OBJ, PLY or OFF)");
  cl.option("output", "PNG", "output picture");
  cl.option("width", "W", "picture width in pixels", "1024");
  cl.option("height", "H", "picture height in pixels", "768");
  cl.option("azimuth", "DEG", "camera angle around the vertical axis", "35");
  cl.option("elevation", "DEG", "camera angle above the horizon", "30");
  cl.option("samples", "N", "samples per pixel (anti-aliasing)", "4");
  cl.option("up", "auto|x|y|z",
            "the mesh's up axis; auto: the thickness axis of flat layers, else y", "auto");
  cl.flag("ground", "draw a ground plane that catches the shadow");
  cl.flag("single-color", "one colour for the whole mesh");
  cl.option("color", "elements|links|shape|single",
            "elements: a colour per element. links: each ring by its link count (0 red, 1 orange, "
            "2 yellow, 3 cyan, 4 green, more blue); with --swatch by its shortfall against its "
            "own kind's interior count in the swatch (as many green, 1 fewer cyan, 2 fewer yellow, "
            "3 fewer orange, none red, more blue); degenerate rings (no hole, folded, not "
            "ring-shaped) magenta; not a ring grey. shape (needs --swatch): each compact element "
            "by its shape against its swatch element at the output's scale: green size ratio "
            "0.9-1.1 and aspect <= 1.1 (as the swatch's), yellow size or aspect off by up to 1.3x, "
            "orange up to 1.5x, red over 1.5x, blue smaller than 1/1.3 with aspect <= 1.3, "
            "magenta degenerate rings, grey not measured (threads, vines). single: one colour",
            "elements");
  cl.option("swatch", "FILE",
            "the swatch the mesh was made from: links judged per kind, and --color shape");
  cl.option("scale", "S",
            "with --swatch and --base: the scale the result was quilted at, as surface --scale "
            "(default: estimated from the element areas)");
  cl.option("crop", "X Y Z R", "show only the elements whose centre lies within R of (X, Y, Z)", "",
            4);
  cl.option("base", "FILE", "also draw this base mesh, in a neutral colour, under the texture");
  cl.flag("quiet", "print nothing but errors");
}

// What the command line asks for: the picture's options (all but the up axis, which may need
// the mesh), the colouring and the scale of --scale (0: none).
struct RenderRequest {
  RenderOptions options;
  std::string color;
  double scale = 0;
};

RenderRequest render_request(const CommandLine& cl) {
  if (!cl.has("output")) throw UsageError("-o PNG is required");
  RenderRequest q;
  RenderOptions& o = q.options;
  o.width = static_cast<int>(cl.get_int("width", 16, 8192));
  o.height = static_cast<int>(cl.get_int("height", 16, 8192));
  o.azimuth_deg = cl.get_double("azimuth", 0, -360, 360);
  o.elevation_deg = cl.get_double("elevation", 0, -89, 89);
  o.samples_per_pixel = static_cast<int>(cl.get_int("samples", 1, 64));
  q.color = cl.has("single-color") ? std::string("single") : cl.get("color");
  if (q.color != "elements" && q.color != "links" && q.color != "shape" && q.color != "single")
    throw UsageError("--color expects elements, links, shape or single, got '" + q.color + "'");
  if (q.color == "shape" && !cl.has("swatch"))
    throw UsageError("--color shape needs --swatch (shapes are measured against its elements)");
  if (cl.has("scale") && !(cl.has("swatch") && cl.has("base")))
    throw UsageError("--scale needs --swatch and --base (it is relative to the base's size)");
  q.scale = cl.has("scale") ? cl.get_double("scale", 0, 1e-12, 1e12) : 0;
  o.color_elements = q.color != "single";
  o.ground_plane = cl.has("ground");
  return q;
}

// --color shape: green within 10% of the swatch element's size and aspect, yellow, orange and
// red further off, blue shrunk, grey not measured.
Rgb shape_color(const ElementStructure& e) {
  const double size = e.size_ratio, aspect = e.aspect;
  const double off = std::max({size, 1 / std::max(size, 1e-300), aspect});
  if (!(size > 0)) return kGrey;
  if (size > 1.5 || aspect > 1.5) return kRed;
  if (size > 1.3 || aspect > 1.3) return kOrange;
  if (size < 1 / 1.3) return kBlue;
  if (off > 1.1 || size < 0.9) return kYellow;
  return kGreen;
}

// --color links for a ring: by its shortfall against its own swatch kind's interior count
// when judged against a swatch, else by its link count.
Rgb link_color(const ElementStructure& e, const std::optional<StructureSummary>& judged) {
  if (!judged) {
    const Rgb* const by_links[] = {&kRed, &kOrange, &kYellow, &kCyan, &kGreen};
    return e.links <= 4 ? *by_links[e.links] : kBlue;
  }
  const SwatchStructure& sw = judged->swatch;
  const int sk = e.swatch_kind;
  const int want = sk >= 0 && sw.kinds[static_cast<size_t>(sk)].interior_links >= 0
                       ? sw.kinds[static_cast<size_t>(sk)].interior_links
                       : sw.interior_links;
  static const Rgb* const by_shortfall[] = {&kGreen, &kCyan, &kYellow, &kOrange};
  if (e.links == 0) return kRed;
  if (e.links > want) return kBlue;
  return *by_shortfall[std::min(3, want - e.links)];
}

// The colour of each element for --color links or shape, measured (against the swatch when
// given); none for the other colourings.
std::vector<Rgb> element_colors(const TriMesh& mesh, const RenderRequest& q,
                                const CommandLine& cl) {
  std::vector<Rgb> colors;
  if (q.color != "links" && q.color != "shape") return colors;
  std::optional<StructureSummary> judged;
  if (cl.has("swatch")) {
    const TriMesh swatch = read_mesh(cl.get("swatch"));
    std::optional<TriMesh> base;
    if (cl.has("base")) base = read_mesh(cl.get("base"));
    const double linear_scale = q.scale > 0 ? swatch_scale_for(*base, swatch, q.scale) : 0;
    judged = summarize_structure(mesh, swatch, base ? &*base : nullptr, linear_scale);
  }
  const StructureReport r = judged ? judged->output : measure_structure(mesh);
  for (const ElementStructure& e : r.elements) {
    if (e.ring && e.degenerate())
      colors.push_back(kMagenta);
    else if (q.color == "shape")
      colors.push_back(shape_color(e));
    else if (!e.ring)
      colors.push_back(kGrey);
    else
      colors.push_back(link_color(e, judged));
  }
  return colors;
}

// --crop: keeps the elements whose centre (mean corner) lies within R of the point, and their
// colours.
void crop_elements(const CommandLine& cl, TriMesh& mesh, std::vector<Rgb>& colors) {
  const Vector3d c(cl.get_double("crop", 0), cl.get_double("crop", 1), cl.get_double("crop", 2));
  const double r = cl.get_double("crop", 3, 0, 1e300);
  std::vector<int> fc;
  const int n = connected_components(mesh.F, mesh.num_vertices(), fc);
  std::vector<Vector3d> sum(n, Vector3d::Zero());
  std::vector<int> count(n, 0);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      sum[fc[f]] += mesh.V.row(mesh.F(f, k)).transpose();
      ++count[fc[f]];
    }
  std::vector<int> faces;
  std::vector<Rgb> kept;
  for (int e = 0; e < n; ++e)
    if ((sum[e] / count[e] - c).norm() <= r && !colors.empty()) kept.push_back(colors[e]);
  for (int f = 0; f < mesh.num_faces(); ++f)
    if ((sum[fc[f]] / count[fc[f]] - c).norm() <= r) faces.push_back(f);
  if (faces.empty()) throw InvalidInput("--crop: no element has its centre within the radius");
  mesh = extract_faces(mesh, faces);
  colors = kept;
}

// --base: the base mesh (cropped like the texture, by face centroid) appended after the
// texture's elements, drawn in the neutral colour.
void append_base(const CommandLine& cl, TriMesh& mesh, RenderOptions& o) {
  TriMesh base = read_mesh(cl.get("base"));
  if (cl.has("crop")) {
    const Vector3d c(cl.get_double("crop", 0), cl.get_double("crop", 1), cl.get_double("crop", 2));
    const double r = cl.get_double("crop", 3, 0, 1e300);
    std::vector<int> faces;
    for (int f = 0; f < base.num_faces(); ++f) {
      const Vector3d m =
          (base.V.row(base.F(f, 0)) + base.V.row(base.F(f, 1)) + base.V.row(base.F(f, 2)))
              .transpose() /
          3.0;
      if ((m - c).norm() <= r) faces.push_back(f);
    }
    base = extract_faces(base, faces);
  }
  if (base.empty()) return;
  std::vector<int> fc;
  o.neutral_from = connected_components(mesh.F, mesh.num_vertices(), fc);
  mesh.N.resize(0, 3);
  base.N.resize(0, 3);
  append_mesh(mesh, base);
}

// --up: the given axis, or for auto the thickness axis of a thin layer (a quilt or a swatch,
// shown from above), else y.
int up_axis(const CommandLine& cl, const TriMesh& mesh) {
  const std::string up = cl.get("up");
  if (up == "x" || up == "y" || up == "z") return up[0] - 'x';
  if (up != "auto") throw UsageError("--up expects auto, x, y or z, got '" + up + "'");
  const Vector3d size = bounding_box(mesh.V, mesh.F).extent();
  int thin = 0;
  for (int k = 1; k < 3; ++k)
    if (size(k) < size(thin)) thin = k;
  return size(thin) < 0.25 * size.maxCoeff() ? thin : 1;
}

}  // namespace

int run_render(int argc, char** argv, int first) {
  CommandLine cl("render", "MESH -o PNG [options]",
                 "Renders a mesh to a PNG preview (Embree ray casting, shadows, each geometry\n"
                 "element in its own colour).");
  declare_render_options(cl);
  if (!cl.parse(argc, argv, first)) return 0;
  RenderRequest q = render_request(cl);
  RenderOptions& o = q.options;
  check_paths({cl.get("output")}, {cl.positional_value("MESH"), cl.get("base"), cl.get("swatch")});
  TriMesh mesh = read_mesh(cl.positional_value("MESH"));
  std::vector<Rgb> colors = element_colors(mesh, q, cl);
  if (cl.has("crop")) crop_elements(cl, mesh, colors);
  o.element_colors = colors;
  if (cl.has("base")) append_base(cl, mesh, o);
  o.up_axis = up_axis(cl, mesh);
  write_png(cl.get("output"), render_mesh(mesh, o));
  if (!cl.has("quiet"))
    std::printf("wrote %s (%dx%d)\n", cl.get("output").c_str(), o.width, o.height);
  return 0;
}

}  // namespace mq::cli
