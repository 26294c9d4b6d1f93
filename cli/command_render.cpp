// meshquilt render MESH -o PNG: a preview picture by Embree ray casting.
#include <cstdio>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/geometry_measures.h"
#include "core/mesh_io.h"
#include "core/render.h"

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
  cl.option("up", "auto|x|y|z", "the mesh's up axis; auto: the thickness axis of flat layers, else y",
            "auto");
  cl.flag("ground", "draw a ground plane that catches the shadow");
  cl.flag("single-color", "one colour for the whole mesh");
  cl.flag("quiet", "print nothing but errors");
  if (!cl.parse(argc, argv, first)) return 0;
  if (!cl.has("output")) throw UsageError("-o PNG is required");
  RenderOptions o;
  o.width = static_cast<int>(cl.get_int("width", 16, 8192));
  o.height = static_cast<int>(cl.get_int("height", 16, 8192));
  o.azimuth_deg = cl.get_double("azimuth", 0, -360, 360);
  o.elevation_deg = cl.get_double("elevation", 0, -89, 89);
  o.samples_per_pixel = static_cast<int>(cl.get_int("samples", 1, 64));
  o.color_elements = !cl.has("single-color");
  o.ground_plane = cl.has("ground");
  const TriMesh mesh = read_mesh(cl.positional_value("MESH"));
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
  if (!cl.has("quiet")) std::printf("wrote %s (%dx%d)\n", cl.get("output").c_str(), o.width, o.height);
  return 0;
}

}  // namespace mq::cli
