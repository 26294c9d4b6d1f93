// meshquilt swatch KIND -o FILE: the sample swatches artists start from.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/run_context.h"
#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"

namespace mq::cli {

namespace {

void declare_swatch_options(CommandLine& cl) {
  cl.positional("KIND", "chainmail | chainmail-square | weave | apples | ivy");
  cl.option("output", "FILE", "output mesh (.obj, .ply, .off or .glb)");
  cl.option("rows", "N", "chainmail(-square): ring rows; weave: threads along x", "6");
  cl.option("cols", "N", "chainmail(-square): ring columns; weave: threads along y", "6");
  cl.option("count", "N", "apples: number of apples; ivy: number of leaves", "24");
  cl.option("scale", "S", "size of one element (ring/apple radius, thread spacing, leaf)", "1");
  cl.option("length", "L", "ivy: vine length in units of --scale", "10");
  cl.option("detail", "N", "segments around a ring/tube or apple resolution", "0");
  cl.option("seed", "N", "random seed (apples, ivy)", "1");
  cl.option("frames", "N",
            "ivy: also a looping wind animation of N frames (leaves lifting and rolling about "
            "where they meet the vine, the vine swaying): -o is then a pattern with one frame "
            "number (%d or %0Nd), frames 0 to N-1 are written, frame 0 the swatch itself; for "
            "'surface --swatch-frames'");
  cl.flag("quiet", "print nothing but errors");
  cl.option("max-faces", "N",
            "refuse a swatch estimated to have more faces (also bounded by the machine's memory)",
            "2e7");
  add_output_options(cl);
}

// The options every kind shares, and the size check each makes before the real swatch.
struct SwatchRequest {
  std::string kind;
  double scale = 1;
  int detail = 0;
  uint64_t seed = 1;
  double limit = 0;
  // The size is estimated from a small swatch of the same kind and detail before the real one
  // is made (issue 14: 200 x 200 rings at --detail 256 would need ~54 GB).
  void check_size(double faces) const {
    MQ_CHECK(faces <= limit, InvalidInput, "this ", kind, " swatch would have about ", faces,
             " faces, more than the limit of ", limit,
             " (--max-faces); use fewer elements or a "
             "lower --detail");
  }
};

// The options both ring patterns share: rows and columns, sizes at --scale, --detail.
template <class RingOptions>
void set_ring_grid(const CommandLine& cl, const SwatchRequest& q, RingOptions& o) {
  o.rows = static_cast<int>(cl.get_int("rows", 1, 200));
  o.cols = static_cast<int>(cl.get_int("cols", 1, 200));
  o.ring_radius *= q.scale;
  o.wire_radius *= q.scale;
  if (q.detail)
    o.ring_segments = std::max(8, q.detail), o.wire_segments = std::max(4, q.detail / 4);
}

TriMesh make_chainmail(const CommandLine& cl, const SwatchRequest& q) {
  ChainMailOptions o;
  set_ring_grid(cl, q, o);
  ChainMailOptions one = o;
  one.rows = one.cols = 1;
  q.check_size(static_cast<double>(chainmail_4in1(one).num_faces()) * o.rows * o.cols);
  return chainmail_4in1(o);
}

TriMesh make_square_mail(const CommandLine& cl, const SwatchRequest& q) {
  SquareMailOptions o;
  set_ring_grid(cl, q, o);
  SquareMailOptions one = o;
  one.rows = one.cols = 1;
  // A flat ring per cell and up to two connectors of as many faces.
  q.check_size(static_cast<double>(chainmail_square(one).num_faces()) *
               (3.0 * o.rows * o.cols - o.rows - o.cols));
  return chainmail_square(o);
}

TriMesh make_weave(const CommandLine& cl, const SwatchRequest& q) {
  WeaveOptions o;
  o.threads_x = static_cast<int>(cl.get_int("rows", 1, 200));
  o.threads_y = static_cast<int>(cl.get_int("cols", 1, 200));
  o.spacing *= q.scale;
  o.thread_radius *= q.scale;
  if (q.detail) o.tube_segments = std::max(4, q.detail);
  WeaveOptions small = o;
  small.threads_x = small.threads_y = 2;
  q.check_size(static_cast<double>(plain_weave(small).num_faces()) * o.threads_x * o.threads_y /
               4.0);
  return plain_weave(o);
}

TriMesh make_apples(const CommandLine& cl, const SwatchRequest& q) {
  AppleOptions o;
  o.count = static_cast<int>(cl.get_int("count", 1, 10000));
  o.mean_radius *= q.scale;
  o.seed = q.seed;
  if (q.detail) o.resolution = std::max(6, q.detail);
  AppleOptions one = o;
  one.count = 1;
  q.check_size(static_cast<double>(apple_layer(one).num_faces()) * o.count);
  return apple_layer(o);
}

TriMesh make_ivy(const CommandLine& cl, const SwatchRequest& q) {
  IvyOptions o;
  o.leaves = cl.has("count") ? static_cast<int>(cl.get_int("count", 0, 10000)) : o.leaves;
  o.length = cl.get_double("length", 0, 1e-3, 1e6) * q.scale;
  o.leaf_size *= q.scale;
  o.seed = q.seed;
  IvyOptions bare = o;  // the vine per unit length, then one leaf
  bare.leaves = 0;
  bare.length = std::min(o.length, 10 * q.scale);
  const double vine = ivy_section(bare).num_faces();
  IvyOptions leafy = bare;
  leafy.leaves = 1;
  const double leaf = std::max(0, ivy_section(leafy).num_faces() - static_cast<int>(vine));
  q.check_size(vine * o.length / bare.length + leaf * o.leaves);
  return ivy_section(o);
}

}  // namespace

int run_swatch(int argc, char** argv, int first) {
  CommandLine cl("swatch", "KIND -o FILE [options]",
                 "Generates a flat, thin sample swatch. KIND is one of:\n"
                 "  chainmail         European 4-in-1 chain mail sheet of closed rings\n"
                 "  chainmail-square  square 4-in-1: flat rings on a square grid, each linked to\n"
                 "                    4 upright connector rings (kinds ring and connector)\n"
                 "  weave             plain weave of interlaced threads\n"
                 "  apples            a layer of apple-like blobs of varied size\n"
                 "  ivy               a vine section with leaves");
  declare_swatch_options(cl);
  if (!cl.parse(argc, argv, first)) return 0;
  if (!cl.has("output")) throw UsageError("-o FILE is required");
  SwatchRequest q;
  q.kind = cl.positional_value("KIND");
  const std::string out = cl.get("output");
  const WriteOptions write_options = output_options(cl);
  // With --frames: one output per frame, each name from the pattern.
  std::vector<std::string> outputs{out};
  if (cl.has("frames")) {
    if (q.kind != "ivy") throw UsageError("--frames animates the ivy swatch only");
    const int frames = static_cast<int>(cl.get_int("frames", 1, 100000));
    const FramePattern name(out, "-o");
    outputs.clear();
    for (int k = 0; k < frames; ++k) outputs.push_back(name(k));
  }
  std::vector<std::string> files;
  for (const std::string& o : outputs) {
    mesh_format_from_path(o);
    for (const std::string& f : output_files(o, write_options)) files.push_back(f);
  }
  check_paths(files, {});
  q.scale = cl.get_double("scale", 0, 1e-6, 1e6);
  q.detail = static_cast<int>(cl.get_int("detail", 0, 256));
  q.seed = static_cast<uint64_t>(cl.get_int("seed", 0, 1LL << 62));
  q.limit = face_limit(cl);
  TriMesh mesh;
  if (q.kind == "chainmail")
    mesh = make_chainmail(cl, q);
  else if (q.kind == "chainmail-square")
    mesh = make_square_mail(cl, q);
  else if (q.kind == "weave")
    mesh = make_weave(cl, q);
  else if (q.kind == "apples")
    mesh = make_apples(cl, q);
  else if (q.kind == "ivy")
    mesh = make_ivy(cl, q);
  else
    throw UsageError("unknown swatch kind '" + q.kind +
                     "' (chainmail, chainmail-square, weave, apples or ivy)");
  IvyWindOptions wind;
  wind.frames = static_cast<int>(outputs.size());
  const std::vector<TriMesh> frames = cl.has("frames") ? ivy_wind(mesh, wind) : std::vector{mesh};
  for (size_t k = 0; k < outputs.size(); ++k) {
    const TriMesh& m = frames[k];
    write_output(outputs[k], m, write_options);
    if (!cl.has("quiet")) {
      std::vector<int> fc;
      const int elements = connected_components(m.F, m.num_vertices(), fc);
      std::printf("wrote %s: %s swatch, %d faces, %d vertices, %d elements\n", outputs[k].c_str(),
                  q.kind.c_str(), m.num_faces(), m.num_vertices(), elements);
    }
  }
  return 0;
}

}  // namespace mq::cli
