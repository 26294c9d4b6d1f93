// meshquilt embed: a saved quilt placed again on its base, moved (posed, sculpted, animated),
// without a new synthesis (issue 25; paper section 3.2: the output lives in local coordinates
// over the base, so only the shell map and the post-processing run again).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/json_writer.h"
#include "cli/run_context.h"
#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/mesh_io.h"
#include "core/shell/follow_base.h"
#include "core/shell/saved_quilt.h"

namespace mq::cli {

namespace {

struct FrameResult {
  int frame = 0;
  std::string base, output;
  FollowBaseStats stats;
  double seconds = 0;
};

void write_stats(const std::string& path, const std::string& quilt_path,
                 const SavedQuiltHeader& header, const std::vector<FrameResult>& frames,
                 int threads, double wall) {
  JsonWriter j;
  j.begin_object()
      .value("command", "embed")
      .value("quilt", quilt_path)
      .value("origin", header.origin)
      .value("threads", threads)
      .value("wall_seconds", wall)
      .begin_array("frames");
  for (const FrameResult& f : frames)
    j.begin_object()
        .value("frame", f.frame)
        .value("base", f.base)
        .value("output", f.output)
        .value("seconds", f.seconds)
        .value("elements", f.stats.elements)
        .value("rigid", f.stats.rigid)
        .value("following", f.stats.following)
        .value("unmoved", f.stats.unmoved)
        .value("unbent", f.stats.unbent)
        .value("shrunk", f.stats.shrunk)
        .value("pressed_pairs", f.stats.pressed_pairs)
        .value("removed", f.stats.num_removed)
        .value("largest_rigid_offset", f.stats.largest_rigid_offset)
        .end_object();
  j.end_array().end_object();
  write_file_atomically(path, j.str());
}

}  // namespace

namespace {

// The command line of `embed`, declared.
CommandLine declare_embed_options() {
  CommandLine cl(
      "embed", "--quilt FILE --base FILE -o OUT [options]",
      "Places a quilt saved by 'meshquilt surface --save-quilt' on its base again, the same\n"
      "mesh with its vertices moved (posed, sculpted, smoothed, animated), without a new\n"
      "synthesis: every output vertex keeps its place in the shell over its base face\n"
      "(face, barycentric coordinates, height along the normals), compact elements (rings,\n"
      "leaves) move rigidly as that place moves (turned and carried by the surface, not\n"
      "stretched), long ones (threads, stems) follow it vertex by vertex. On the unchanged\n"
      "base the output is the synthesis's, byte for byte. A base of other connectivity is\n"
      "refused.\n"
      "\n"
      "Sequences: with --frames A-B, --base and -o are patterns with one frame number (%d or\n"
      "%0Nd) and each frame is written on its own, with the same faces and element order in\n"
      "every frame (a mesh cache). A render farm hands each process a range:\n"
      "  meshquilt embed --quilt q.mqq --base 'walk_%04d.obj' --frames 1-24 -o 'mail_%04d.ply'\n"
      "Every frame's base is read and checked before the first is written; each output is\n"
      "written whole or not at all, so a failed frame can be run again on its own.");
  cl.option("quilt", "FILE", "a quilt saved by 'surface --save-quilt'");
  cl.option("base", "FILE", "the base, its vertices moved (a pattern with --frames)");
  cl.option("output", "FILE", "output mesh (.obj, .ply, .off, .glb; a pattern with --frames)");
  cl.option("frames", "A-B", "embed frames A to B of the --base pattern, one output each");
  cl.flag("keep-elements",
          "never remove an element (every output has the quilt's faces and element ids: a "
          "result bound to an animated base): those that would go stay shrunk to 60%, pressed "
          "into a neighbour");
  cl.flag("keep-intersecting",
          "keep elements as moved even where they press into a neighbour (by default a rigid "
          "element that would follows the surface instead, and one that still does is removed, "
          "in every frame of a sequence)");
  cl.option("rigid-radius", "R",
            "elements within R shell heights of their centre move rigidly; 0: all follow the "
            "surface vertex by vertex",
            "3");
  add_output_options(cl);
  add_run_options(cl);
  return cl;
}

// The placement's options from the command line.
FollowBaseOptions following_options(const CommandLine& cl) {
  FollowBaseOptions follow;
  follow.rigid_radius = cl.get_double("rigid-radius", 0, 0.0, 1e6);
  follow.resolve_intersections = !cl.has("keep-intersecting");
  follow.keep_elements = cl.has("keep-elements");
  return follow;
}

// The frames: one (the base and output as given) or a range over two patterns.
std::vector<FrameResult> requested_frames(const CommandLine& cl) {
  std::vector<FrameResult> frames;
  if (cl.has("frames")) {
    const auto [a, b] = frame_range(cl.get("frames"));
    const FramePattern base_name(cl.get("base"), "--base"), out_name(cl.get("output"), "-o");
    for (int f = a; f <= b; ++f) frames.push_back({f, base_name(f), out_name(f), {}, 0});
  } else {
    frames.push_back({0, cl.get("base"), cl.get("output"), {}, 0});
  }
  return frames;
}

// Every output's format known and no output naming an input, before any work.
void check_embed_paths(const CommandLine& cl, const std::vector<FrameResult>& frames,
                       const WriteOptions& write_options) {
  std::vector<std::string> outputs, inputs{cl.get("quilt")};
  for (const FrameResult& f : frames) {
    mesh_format_from_path(f.output);
    for (const std::string& file : output_files(f.output, write_options)) outputs.push_back(file);
    inputs.push_back(f.base);
  }
  outputs.push_back(cl.get("stats"));
  check_paths(outputs, inputs);
}

// A frame's base as the quilt's welded base moved; its errors name the file.
MatrixX3d frame_positions(const SavedQuilt& saved, const FrameResult& f) {
  try {
    return welded_positions(saved, read_mesh(f.base));
  } catch (const InvalidInput& e) {
    MQ_THROW(InvalidInput, f.base, ": ", e.what());
  }
}

// A sequence removes in every frame what any frame removes (a mesh cache keeps its faces): a
// first pass finds them.
std::vector<char> removed_in_any_frame(const SavedQuilt& saved,
                                       const std::vector<FrameResult>& frames,
                                       const FollowBaseOptions& follow) {
  std::vector<char> removed;
  for (const FrameResult& f : frames) {
    FollowBaseStats pass;
    follow_base(saved, frame_positions(saved, f), follow, &pass);
    removed.resize(pass.removed.size(), 0);
    for (size_t e = 0; e < removed.size(); ++e) removed[e] |= pass.removed[e];
  }
  return removed;
}

// One frame placed and written whole, with its summary line.
void embed_frame(RunContext& run, const SavedQuilt& saved, const FollowBaseOptions& follow,
                 const WriteOptions& write_options, FrameResult& f) {
  const auto frame_start = std::chrono::steady_clock::now();
  const MatrixX3d V = frame_positions(saved, f);
  const TriMesh result = follow_base(saved, V, follow, &f.stats);
  {
    ScopedStageProgress shown(run.progress(), Stage::Writing);
    write_output(f.output, result, write_options);
  }
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - frame_start).count();
  if (!run.quiet())
    std::printf(
        "wrote %s: %d faces, %d vertices, %d elements (%d moved rigidly, %d following the "
        "surface, %d unmoved; %d pressed into a neighbour made to follow the surface, %d "
        "shrunk, %d removed); %.2f s\n",
        f.output.c_str(), result.num_faces(), result.num_vertices(),
        f.stats.elements - f.stats.num_removed, f.stats.rigid, f.stats.following, f.stats.unmoved,
        f.stats.unbent, f.stats.shrunk, f.stats.num_removed, f.seconds);
}

}  // namespace

int run_embed(int argc, char** argv, int first) {
  CommandLine cl = declare_embed_options();
  if (!cl.parse(argc, argv, first)) return 0;
  if (!cl.has("quilt")) throw UsageError("--quilt FILE is required");
  if (!cl.has("base")) throw UsageError("--base FILE is required");
  if (!cl.has("output")) throw UsageError("-o OUT is required");
  const WriteOptions write_options = output_options(cl);
  FollowBaseOptions follow = following_options(cl);
  std::vector<FrameResult> frames = requested_frames(cl);
  check_embed_paths(cl, frames, write_options);

  RunContext run(cl);
  const auto start = std::chrono::steady_clock::now();
  const SavedQuilt saved = read_saved_quilt(cl.get("quilt"));
  // Every frame's base read and checked first: a missing or mismatched frame fails the run
  // before anything is written.
  if (frames.size() > 1)
    for (const FrameResult& f : frames) frame_positions(saved, f);
  if (frames.size() > 1 && follow.resolve_intersections && !follow.keep_elements)
    follow.remove = removed_in_any_frame(saved, frames, follow);
  for (FrameResult& f : frames) embed_frame(run, saved, follow, write_options, f);
  run.progress()->finish();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!run.stats_path().empty())
    write_stats(run.stats_path(), cl.get("quilt"), saved.header, frames, run.threads(), wall);
  return 0;
}

}  // namespace mq::cli
