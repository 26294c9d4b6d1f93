// meshquilt swatch KIND -o FILE: the sample swatches artists start from.
#include <cstdio>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/mesh_io.h"
#include "core/mesh_topology.h"
#include "core/swatch_generators.h"

namespace mq::cli {

int run_swatch(int argc, char** argv, int first) {
  CommandLine cl("swatch", "KIND -o FILE [options]",
                 "Generates a flat, thin sample swatch. KIND is one of:\n"
                 "  chainmail  European 4-in-1 chain mail sheet of closed rings\n"
                 "  weave      plain weave of interlaced threads\n"
                 "  apples     a layer of apple-like blobs of varied size\n"
                 "  ivy        a vine section with leaves");
  cl.positional("KIND", "chainmail | weave | apples | ivy");
  cl.option("output", "FILE", "output mesh (.obj, .ply or .off)");
  cl.option("rows", "N", "chainmail: ring rows; weave: threads along x", "6");
  cl.option("cols", "N", "chainmail: ring columns; weave: threads along y", "6");
  cl.option("count", "N", "apples: number of apples; ivy: number of leaves", "24");
  cl.option("scale", "S", "size of one element (ring/apple radius, thread spacing, leaf)", "1");
  cl.option("length", "L", "ivy: vine length in units of --scale", "10");
  cl.option("detail", "N", "segments around a ring/tube or apple resolution", "0");
  cl.option("seed", "N", "random seed (apples, ivy)", "1");
  cl.flag("quiet", "print nothing but errors");
  if (!cl.parse(argc, argv, first)) return 0;
  if (!cl.has("output")) throw UsageError("-o FILE is required");
  const std::string kind = cl.positional_value("KIND");
  const std::string out = cl.get("output");
  mesh_format_from_path(out);
  const double scale = cl.get_double("scale", 0, 1e-6, 1e6);
  const int detail = static_cast<int>(cl.get_int("detail", 0, 256));
  const auto seed = static_cast<uint64_t>(cl.get_int("seed", 0, 1LL << 62));
  TriMesh mesh;
  if (kind == "chainmail") {
    ChainMailOptions o;
    o.rows = static_cast<int>(cl.get_int("rows", 1, 200));
    o.cols = static_cast<int>(cl.get_int("cols", 1, 200));
    o.ring_radius *= scale;
    o.wire_radius *= scale;
    if (detail) o.ring_segments = std::max(8, detail), o.wire_segments = std::max(4, detail / 4);
    mesh = chainmail_4in1(o);
  } else if (kind == "weave") {
    WeaveOptions o;
    o.threads_x = static_cast<int>(cl.get_int("rows", 1, 200));
    o.threads_y = static_cast<int>(cl.get_int("cols", 1, 200));
    o.spacing *= scale;
    o.thread_radius *= scale;
    if (detail) o.tube_segments = std::max(4, detail);
    mesh = plain_weave(o);
  } else if (kind == "apples") {
    AppleOptions o;
    o.count = static_cast<int>(cl.get_int("count", 1, 10000));
    o.mean_radius *= scale;
    o.seed = seed;
    if (detail) o.resolution = std::max(6, detail);
    mesh = apple_layer(o);
  } else if (kind == "ivy") {
    IvyOptions o;
    o.leaves = cl.has("count") ? static_cast<int>(cl.get_int("count", 0, 10000)) : o.leaves;
    o.length = cl.get_double("length", 0, 1e-3, 1e6) * scale;
    o.leaf_size *= scale;
    o.seed = seed;
    mesh = ivy_section(o);
  } else {
    throw UsageError("unknown swatch kind '" + kind + "' (chainmail, weave, apples or ivy)");
  }
  write_mesh(out, mesh);
  if (!cl.has("quiet")) {
    std::vector<int> fc;
    const int elements = connected_components(mesh.F, mesh.num_vertices(), fc);
    std::printf("wrote %s: %s swatch, %d faces, %d vertices, %d elements\n", out.c_str(),
                kind.c_str(), mesh.num_faces(), mesh.num_vertices(), elements);
  }
  return 0;
}

}  // namespace mq::cli
