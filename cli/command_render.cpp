// meshquilt render MESH -o PNG: a preview picture by Embree ray casting.
#include <algorithm>
#include <cstdio>
#include <optional>

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

int run_render(int argc, char** argv, int first) {
  CommandLine cl("render", "MESH -o PNG [options]",
                 "Renders a mesh to a PNG preview (Embree ray casting, shadows, each geometry\n"
                 "element in its own colour).");
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
  if (!cl.parse(argc, argv, first)) return 0;
  if (!cl.has("output")) throw UsageError("-o PNG is required");
  RenderOptions o;
  o.width = static_cast<int>(cl.get_int("width", 16, 8192));
  o.height = static_cast<int>(cl.get_int("height", 16, 8192));
  o.azimuth_deg = cl.get_double("azimuth", 0, -360, 360);
  o.elevation_deg = cl.get_double("elevation", 0, -89, 89);
  o.samples_per_pixel = static_cast<int>(cl.get_int("samples", 1, 64));
  const std::string color = cl.has("single-color") ? std::string("single") : cl.get("color");
  if (color != "elements" && color != "links" && color != "shape" && color != "single")
    throw UsageError("--color expects elements, links, shape or single, got '" + color + "'");
  if (color == "shape" && !cl.has("swatch"))
    throw UsageError("--color shape needs --swatch (shapes are measured against its elements)");
  if (cl.has("scale") && !(cl.has("swatch") && cl.has("base")))
    throw UsageError("--scale needs --swatch and --base (it is relative to the base's size)");
  const double scale = cl.has("scale") ? cl.get_double("scale", 0, 1e-12, 1e12) : 0;
  o.color_elements = color != "single";
  o.ground_plane = cl.has("ground");
  check_paths({cl.get("output")}, {cl.positional_value("MESH"), cl.get("base"), cl.get("swatch")});
  TriMesh mesh = read_mesh(cl.positional_value("MESH"));
  std::vector<std::array<unsigned char, 3>> colors;
  if (color == "links" || color == "shape") {
    using Rgb = std::array<unsigned char, 3>;
    const Rgb red{{220, 40, 40}}, orange{{240, 140, 30}}, yellow{{225, 205, 40}},
        cyan{{60, 200, 220}}, green{{40, 170, 60}}, blue{{50, 80, 220}}, grey{{150, 150, 150}},
        magenta{{200, 50, 200}};
    std::optional<StructureSummary> judged;
    if (cl.has("swatch")) {
      const TriMesh swatch = read_mesh(cl.get("swatch"));
      std::optional<TriMesh> base;
      if (cl.has("base")) base = read_mesh(cl.get("base"));
      const double linear_scale = scale > 0 ? swatch_scale_for(*base, swatch, scale) : 0;
      judged = summarize_structure(mesh, swatch, base ? &*base : nullptr, linear_scale);
    }
    const StructureReport r = judged ? judged->output : measure_structure(mesh);
    for (const ElementStructure& e : r.elements) {
      if (e.ring && e.degenerate()) {
        colors.push_back(magenta);
      } else if (color == "shape") {
        const double size = e.size_ratio, aspect = e.aspect;
        const double off = std::max({size, 1 / std::max(size, 1e-300), aspect});
        if (!(size > 0))
          colors.push_back(grey);
        else if (size > 1.5 || aspect > 1.5)
          colors.push_back(red);
        else if (size > 1.3 || aspect > 1.3)
          colors.push_back(orange);
        else if (size < 1 / 1.3)
          colors.push_back(blue);
        else if (off > 1.1 || size < 0.9)
          colors.push_back(yellow);
        else
          colors.push_back(green);
      } else if (!e.ring) {
        colors.push_back(grey);
      } else if (judged) {
        const SwatchStructure& sw = judged->swatch;
        const int sk = e.swatch_kind;
        const int want = sk >= 0 && sw.kinds[static_cast<size_t>(sk)].interior_links >= 0
                             ? sw.kinds[static_cast<size_t>(sk)].interior_links
                             : sw.interior_links;
        static const Rgb* const by_shortfall[] = {&green, &cyan, &yellow, &orange};
        if (e.links == 0)
          colors.push_back(red);
        else if (e.links > want)
          colors.push_back(blue);
        else
          colors.push_back(*by_shortfall[std::min(3, want - e.links)]);
      } else {
        const Rgb* const by_links[] = {&red, &orange, &yellow, &cyan, &green};
        colors.push_back(e.links <= 4 ? *by_links[e.links] : blue);
      }
    }
  }
  if (cl.has("crop")) {
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
    std::vector<std::array<unsigned char, 3>> kept;
    for (int e = 0; e < n; ++e)
      if ((sum[e] / count[e] - c).norm() <= r && !colors.empty()) kept.push_back(colors[e]);
    for (int f = 0; f < mesh.num_faces(); ++f)
      if ((sum[fc[f]] / count[fc[f]] - c).norm() <= r) faces.push_back(f);
    if (faces.empty()) throw InvalidInput("--crop: no element has its centre within the radius");
    mesh = extract_faces(mesh, faces);
    colors = kept;
  }
  o.element_colors = colors;
  if (cl.has("base")) {
    TriMesh base = read_mesh(cl.get("base"));
    if (cl.has("crop")) {
      const Vector3d c(cl.get_double("crop", 0), cl.get_double("crop", 1),
                       cl.get_double("crop", 2));
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
    if (!base.empty()) {
      std::vector<int> fc;
      o.neutral_from = connected_components(mesh.F, mesh.num_vertices(), fc);
      mesh.N.resize(0, 3);
      base.N.resize(0, 3);
      append_mesh(mesh, base);
    }
  }
  const std::string up = cl.get("up");
  if (up == "x" || up == "y" || up == "z") {
    o.up_axis = up[0] - 'x';
  } else if (up == "auto") {
    // A thin layer (a quilt or a swatch) is shown from above its thickness axis.
    const Vector3d size = bounding_box(mesh.V, mesh.F).extent();
    int thin = 0;
    for (int k = 1; k < 3; ++k)
      if (size(k) < size(thin)) thin = k;
    o.up_axis = size(thin) < 0.25 * size.maxCoeff() ? thin : 1;
  } else {
    throw UsageError("--up expects auto, x, y or z, got '" + up + "'");
  }
  write_png(cl.get("output"), render_mesh(mesh, o));
  if (!cl.has("quiet"))
    std::printf("wrote %s (%dx%d)\n", cl.get("output").c_str(), o.width, o.height);
  return 0;
}

}  // namespace mq::cli
