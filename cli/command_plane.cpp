// meshquilt plane: planar mesh quilting (paper section 2).
#include <chrono>
#include <cstdio>
#include <numeric>
#include <optional>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/json_writer.h"
#include "cli/run_context.h"
#include "cli/stats_json.h"
#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/mesh_io.h"
#include "core/planar/planar_quilting.h"
#include "core/shell/swatch_animation.h"
#include "core/structure/texture_structure.h"
#include "host/translation_cost_evaluator.h"

namespace mq::cli {

namespace {

// The --stats file's JSON (written with the mesh, as one commit).
std::string stats_json(const PlanarQuiltingStats& s, const std::string& device, int threads,
                       double wall, const std::string& swatch, double length, double width,
                       const StructureSummary& structure,
                       const std::vector<StructureShortfall>& shortfalls,
                       const ElementDetail& detail, double detail_share) {
  JsonWriter j;
  j.begin_object()
      .value("command", "plane")
      .value("swatch", swatch)
      .value("length", length)
      .value("width", width)
      .value("device", device)
      .value("threads", threads)
      .value("wall_seconds", wall)
      .value("cell_size", s.cell_size)
      .value("grid_nx", s.grid_nx)
      .value("grid_ny", s.grid_ny)
      .value("iterations", s.iterations)
      .begin_object("output")
      .value("faces", s.faces)
      .value("vertices", s.vertices)
      .value("elements", s.elements)
      .end_object()
      .begin_object("elements");
  write_element_counts(j, s.counts);
  j.value("removed_post", s.removed_post).value("trimmed", s.trimmed).end_object();
  write_match_counts(j, s.counts);
  j.value("matched_point_offsets", s.matched_point_offsets);
  write_structure(j, structure.output, &structure.swatch, &structure.comparison);
  write_structure_check(j, shortfalls);
  write_detail(j, detail, detail_share);
  j.begin_object("stage_seconds");
  for (const auto& [stage, seconds] : s.times.stages()) j.value(stage, seconds);
  j.end_object().end_object();
  return j.str();
}

// The structure figures and the run's own check of them (issue 23, as `surface`), not part of
// the run's wall time (returns the seconds taken); the stats then land with the mesh as one
// commit (issue 28), made once it is written.
double measure_structure(const TriMesh& result, const TriMesh& swatch, PlanarQuiltingStats& stats,
                         StructureSummary& structure, std::vector<StructureShortfall>& shortfalls) {
  const auto t0 = std::chrono::steady_clock::now();
  ScopedStageTimer timer(stats.times, Stage::Structure);
  structure = summarize_structure(result, swatch, nullptr, 1.0);
  shortfalls = check_structure(structure);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void declare_plane_options(CommandLine& cl) {
  cl.option("swatch", "FILE", "input swatch mesh (OBJ, PLY or OFF)");
  cl.option("size", "L W", "output extent along the swatch's two long axes", "", 2);
  cl.option("output", "FILE", "output mesh (.obj, .ply, .off or .glb)");
  cl.option("seed", "N", "random seed (used with --variety)", "1");
  cl.option("cell", "SIZE", "grid cell size (default: from the swatch's element size)");
  cl.option("variety", "EPS", "choose randomly among offsets within (1+EPS) of the best", "0");
  cl.option("subpatch", "FRACTION", "sub-patch side as a fraction of the swatch side", "0.5");
  cl.option("device", "auto|cpu|opencl",
            "where large translation-cost evaluations run (small ones stay on the CPU)", "auto");
  cl.flag("no-deform", "skip element deformation (section 2.6)");
  cl.flag("trim", "cut elements crossing the domain border open (default: keep them whole)");
  cl.option("swatch-frames", "PATTERN",
            "animate the layer with the swatch: frames of the swatch, the same mesh with its "
            "vertices moved, named by a pattern with one frame number (%d or %0Nd). Each output "
            "vertex moves as the point of the swatch it came from; with --frames A-B, -o is a "
            "pattern too and one output is written per frame (same faces and element order)");
  cl.option("frames", "A-B", "the frames of --swatch-frames to follow, one output each");
  add_detail_option(cl);
  add_output_options(cl);
  add_run_options(cl);
}

// The quilting options the command line gives (each value checked against its range).
PlanarQuiltingOptions plane_options(const CommandLine& cl) {
  PlanarQuiltingOptions options;
  options.length = cl.get_double("size", 0, 1e-300, 1e300);
  options.width = cl.get_double("size", 1, 1e-300, 1e300);
  options.seed = static_cast<uint64_t>(cl.get_int("seed", 0, (1LL << 62)));
  if (cl.has("cell")) options.cell_size = cl.get_double("cell", 0, 1e-300, 1e300);
  options.matching.epsilon = cl.get_double("variety", 0, 0.0, 10.0);
  options.subpatch_fraction = cl.get_double("subpatch", 0, 0.01, 1.0);
  options.deform = !cl.has("no-deform");
  options.trim_border = cl.has("trim");
  options.max_faces = face_limit(cl);
  return options;
}

// --swatch-frames (issue 25): the layer's vertices located in the swatch and the frames' motions,
// settled so that no element meets another in any frame. frames: the swatch frames as read.
SwatchAnimation animate_layer(const TriMesh& layer, const PlaneSources& sources,
                              const TriMesh& swatch, const std::vector<SwatchFrame>& requested,
                              const std::vector<TriMesh>& frames,
                              std::vector<SwatchMotion>& motions, SettledMotionStats& settled) {
  // The layer's normal: the swatch's thickness axis, in its own axes (prepare_swatch's z).
  const Vector3d normal = prepare_swatch(swatch).rotation.row(2).transpose();
  const SurfaceQuilt quilt = layer_quilt(layer, sources, normal);
  std::vector<int> kept(quilt.elements.size());
  std::iota(kept.begin(), kept.end(), 0);
  SwatchAnimation animation(quilt, kept, layer, swatch, 1.0);
  for (size_t k = 0; k < frames.size(); ++k)
    motions.push_back(swatch_motion(swatch, frames[k], 1.0, requested[k].swatch));
  animation.settle(motions, &settled);
  return animation;
}

// The two lines a run prints unless --quiet (the structure follows with --stats).
void print_plane_summary(const std::string& out_path, const PlanarQuiltingStats& stats, double wall,
                         const std::string& device, int threads) {
  std::printf("wrote %s: %d faces, %d vertices, %d elements\n", out_path.c_str(), stats.faces,
              stats.vertices, stats.elements);
  std::printf(
      "%d iterations in %.2f s on %s (%d threads); elements: %d stitched, %d replaced, "
      "%d added, %d matched, %d removed\n",
      stats.iterations, wall, device.c_str(), threads, stats.counts.stitched, stats.counts.replaced,
      stats.counts.added, stats.counts.matched, stats.removed_post);
}

// Every file the run writes (the mesh or each frame's, their .mtl, the stats) checked against
// the inputs and for a known format before any work.
void check_plane_paths(const CommandLine& cl, const std::vector<SwatchFrame>& requested,
                       const std::string& out_path, const WriteOptions& write_options) {
  std::vector<std::string> outputs, inputs{cl.get("swatch")};
  for (const SwatchFrame& f : requested) inputs.push_back(f.swatch);
  if (requested.empty()) {
    mesh_format_from_path(out_path);  // fail on an unknown extension before any work
    for (const std::string& file : output_files(out_path, write_options)) outputs.push_back(file);
  }
  for (const SwatchFrame& f : requested) {
    mesh_format_from_path(f.output);
    for (const std::string& file : output_files(f.output, write_options)) outputs.push_back(file);
  }
  outputs.push_back(cl.get("stats"));
  check_paths(outputs, inputs);
}

}  // namespace

int run_plane(int argc, char** argv, int first) {
  CommandLine cl(
      "plane", "--swatch FILE --size L W -o OUT [options]",
      "Grows a swatch (any mesh file; its smallest bounding-box side is the layer's\n"
      "thickness) into a seamless L x W layer in the swatch's units, by mesh quilting\n"
      "(seed finding, geometry matching, element correspondences, deformation, merging).");
  declare_plane_options(cl);
  if (!cl.parse(argc, argv, first)) return 0;
  if (!cl.has("swatch")) throw UsageError("--swatch FILE is required");
  if (!cl.has("size")) throw UsageError("--size L W is required");
  if (!cl.has("output")) throw UsageError("-o OUT is required");
  const std::vector<SwatchFrame> requested = requested_swatch_frames(cl);
  const std::string out_path = requested.empty() ? cl.get("output") : requested.front().output;
  const WriteOptions write_options = output_options(cl);
  check_plane_paths(cl, requested, out_path, write_options);

  const PlanarQuiltingOptions options = plane_options(cl);
  const double detail = detail_share(cl);
  const Device device = parse_device(cl.get("device"));

  RunContext run(cl);
  const auto start = std::chrono::steady_clock::now();
  const ElementDetail swatch_detail = read_swatch(cl.get("swatch"), detail);
  const TriMesh& swatch = swatch_detail.mesh;
  std::vector<TriMesh> frames;  // with --swatch-frames: each as read, checked before any work
  for (const SwatchFrame& f : requested) {
    frames.push_back(read_mesh(f.swatch));
    check_swatch_frame(swatch, frames.back(), f.swatch);
  }
  std::unique_ptr<TranslationCostEvaluator> evaluator = make_translation_cost_evaluator(device);
  PlanarQuiltingStats stats;
  PlaneSources sources;
  const TriMesh result = quilt_plane(swatch, options, *evaluator, &stats, run.progress(),
                                     requested.empty() ? nullptr : &sources);
  // A run that makes no geometry is an error, not an empty file (issue 14).
  MQ_CHECK(result.num_faces() > 0, InvalidInput,
           "the layer is empty: no element of the swatch fits the ", options.length, " x ",
           options.width, " domain; nothing written");
  StructureSummary structure;
  std::vector<StructureShortfall> shortfalls;
  const double measuring = measure_structure(result, swatch, stats, structure, shortfalls);
  // The mesh and the --stats file are one commit (issue 28); with --swatch-frames the mesh is
  // the first frame's, and the others follow.
  std::optional<SwatchAnimation> animation;
  std::vector<SwatchMotion> motions;
  SettledMotionStats settled;
  if (!requested.empty()) {
    ScopedStageTimer timer(stats.times, Stage::Animation);
    animation = animate_layer(result, sources, swatch, requested, frames, motions, settled);
  }
  const auto frame = [&](size_t k) { return animation->frame(motions[k]); };
  const double wall =
      write_output_and_stats(run, out_path, animation ? frame(0) : result, write_options,
                             stats.times, start, measuring, [&](double w) {
                               return stats_json(stats, evaluator->name(), run.threads(), w,
                                                 cl.get("swatch"), options.length, options.width,
                                                 structure, shortfalls, swatch_detail, detail);
                             });
  for (size_t k = 1; k < requested.size(); ++k) {
    ScopedStageProgress shown(run.progress(), Stage::Writing);
    write_output(requested[k].output, frame(k), write_options);
  }
  run.progress()->finish();
  if (!run.quiet()) {
    print_detail(swatch_detail, detail);
    print_plane_summary(out_path, stats, wall, evaluator->name(), run.threads());
    if (!requested.empty()) print_swatch_animation(requested, settled);
    print_run_structure(structure, !run.stats_path().empty());
  }
  // A swatch of few elements leaves the patches little to match across their overlaps.
  warn_structure("plane", shortfalls, "a swatch of more elements gives the patches more to match");
  return 0;
}

}  // namespace mq::cli
