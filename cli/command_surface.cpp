// meshquilt surface: mesh quilting over a base mesh (paper section 3.1).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/huge_pages.h"
#include "cli/json_writer.h"
#include "cli/result_check.h"
#include "cli/run_context.h"
#include "cli/stats_json.h"
#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/shell/follow_base.h"
#include "core/shell/quilt_embedding.h"
#include "core/shell/saved_quilt.h"
#include "core/shell/surface_coverage.h"
#include "core/shell/swatch_animation.h"
#include "core/structure/texture_structure.h"
#include "core/surface/global_quilting.h"
#include "core/surface/surface_mask.h"
#include "core/surface/surface_quilting.h"
#include "core/surface/tangent_field.h"
#include "core/surface/vertex_map_io.h"
#include "core/surface/vine_growth.h"
#include "host/tet_stretch_evaluator.h"
#include "host/translation_cost_evaluator.h"

namespace mq::cli {

namespace {

// The --stats file's JSON (written with the mesh, as one commit).
// The base's preparation and the synthesis's parameters (flat values of the stats object).
void write_preparation(JsonWriter& j, const SurfaceQuiltingStats& s) {
  j.value("base_faces", s.base_faces)
      .value("welded_vertices", s.welded_vertices)
      .value("duplicate_faces", s.duplicate_faces)
      .value("sheet_back_faces", s.sheet_back_faces)
      .value("flipped_components", s.flipped_components)
      .value("fin_faces", s.fin_faces)
      .value("fin_area_share", s.fin_area_share)
      .value("non_manifold_edges", s.non_manifold_edges)
      .value("proxy_faces", s.proxy_faces)
      .value("proxy_error", s.proxy_error)
      .value("swatch_scale", s.swatch_scale)
      .value("shell_height", s.shell_height)
      .value("cell_size", s.cell_size)
      .value("iterations", s.iterations)
      .value("patches_shrunk", s.patches_shrunk)
      .value("patch_faces", s.patch_faces);
}

// The shell map's figures (section 3.2).
void write_shell_map(JsonWriter& j, const QuiltEmbeddingStats& em, const std::string& embedding) {
  j.value("embedding", em.shell_map_failure.empty() ? embedding : std::string("normal"))
      .value("shell_map_failure", em.shell_map_failure)
      .value("stretch_before", em.stretch_before)
      .value("stretch_after", em.stretch_after)
      .value("stretch_optimization_sweeps", em.optimization_sweeps)
      .value("atlas_charts", em.atlas_charts)
      .value("shell_smoothing_steps", em.shell_smoothing_steps)
      .value("fold_repaired_vertices", em.fold_repaired_vertices);
}

// The output's size, and the "elements" object: what the planar steps did and what the
// embedding's repairs and post-processing did to elements.
void write_element_figures(JsonWriter& j, const SurfaceQuiltingStats& s,
                           const QuiltEmbeddingStats& em) {
  j.begin_object("output")
      .value("faces", em.faces)
      .value("vertices", em.vertices)
      .value("elements", em.elements)
      .end_object()
      .begin_object("elements");
  write_element_counts(j, s.counts);
  j.value("rejected_outside_patch", s.rejected_outside_patch)
      .value("removed_post", em.removed_intersecting)
      .value("removed_self_intersecting", em.removed_self_intersecting)
      .value("rigid_repairs", em.rigid_repairs)
      .value("shrunk_to_fit", em.shrunk_to_fit)
      .value("linked_versions", em.linked_versions)
      .value("layout_versions", em.layout_versions)
      .value("folded_rings", em.folded_rings)
      .value("unbent_rings", em.unbent_rings)
      .value("late_unbent_rings", em.late_unbent_rings)
      .value("late_unbending_reverted", em.late_unbending_reverted)
      .value("separated_rings", em.separated_rings)
      .value("separation_reverted", em.separation_reverted)
      .value("separation_left_shell", em.separation_left_shell)
      .value("separation_iterations", em.separation_iterations)
      .value("unoptimized_map", em.unoptimized_elements)
      .end_object()
      .begin_object("element_area")
      .value("mean", em.element_area_mean)
      .value("cv", em.element_area_cv)
      .value("min", em.element_area_min)
      .value("max", em.element_area_max)
      .end_object();
}

// The embedding's check of its own result (issue 23): where the shell map was not built, and
// the output's signed heights over the base as given.
void write_placement(JsonWriter& j, const QuiltEmbeddingStats& em, const std::string& embedding) {
  j.begin_object("placement")
      .value("shell_map", embedding != "shell"            ? "not asked"
                          : !em.shell_map_failure.empty() ? "failed"
                          : em.fallback_faces > 0         ? "partial"
                                                          : "whole base")
      .value("fallback_faces", em.fallback_faces)
      .value("fallback_area_share", em.fallback_area_share)
      .value("fallback_fold_faces", em.fallback_fold_faces)
      .value("fallback_reason", em.fallback_reason)
      .value("fallback_elements", em.fallback_elements)
      .value("tolerance", em.placement_tolerance)
      .value("below_base_embedded", em.below_base_embedded)
      .value("replaced_below", em.replaced_below)
      .value("lifted_below", em.lifted_below)
      .value("removed_below", em.removed_below)
      .value("vertices", em.checked_vertices)
      .value("below_base", em.below_base)
      .value("above_shell", em.above_shell)
      .value("lowest_height", em.lowest_height)
      .end_object();
}

// The global layout's figures: its cones, cut, scale, and what it placed.
void write_global_layout(JsonWriter& j, const GlobalQuiltingStats& g) {
  j.begin_object("global")
      .value("periodic", g.periodic)
      .value("seamless", g.seamless)
      .value("tiled", g.tiled)
      .value("orbits", g.orbits)
      .value("singular_vertices", g.singular_vertices)
      .value("cancelled_cone_pairs", g.cancelled_cone_pairs)
      .value("split_poles", g.split_poles)
      .value("cone_moves", g.cone_moves)
      .value("placement_pairs_cancelled", g.placement_pairs_cancelled)
      .value("scale_energy_before", g.scale_energy_before)
      .value("scale_energy", g.scale_energy)
      .value("scale_exponent", g.scale_exponent)
      .value("pinned_cones", g.pinned_cones)
      .value("cut_edges", g.cut_edges)
      .value("cut_paths", g.cut_paths)
      .value("worst_transition_error", g.worst_transition_error)
      .value("scale_correction", g.scale_correction)
      .value("parameter_area", g.parameter_area)
      .value("placed", g.placed)
      .value("off_surface", g.off_surface)
      .value("copied_elements", g.copied_elements)
      .value("threads", g.threads)
      .value("thread_pieces", g.thread_pieces)
      .value("pieces_distorted", g.pieces_distorted)
      .value("pieces_near_cones", g.pieces_near_cones)
      .value("pieces_intersecting", g.pieces_intersecting)
      .value("thread_welds", g.thread_welds)
      .value("thread_ends", g.thread_ends)
      .value("closed_threads", g.closed_threads)
      .value("short_threads", g.short_threads);
  j.begin_array("cones");
  for (Eigen::Index i = 0; i < g.cones.rows(); ++i)
    j.begin_array()
        .value("", g.cones(i, 0))
        .value("", g.cones(i, 1))
        .value("", g.cones(i, 2))
        .end_array();
  j.end_array().end_object();
}

std::string stats_json(const SurfaceQuiltingStats& s, const QuiltEmbeddingStats& em,
                       const std::string& embedding, const std::string& device, int threads,
                       double wall, const std::string& base, const std::string& swatch,
                       const std::string& method, const GlobalQuiltingStats* global,
                       const StructureSummary& structure,
                       const std::vector<StructureShortfall>& shortfalls, double memory_limit_bytes,
                       double min_coverage, double swatch_cover, const ElementDetail& detail,
                       double detail_share) {
  // The global layout counts its output exactly before building it; else the estimate made
  // before any work.
  const double estimated_faces =
      global && global->layout_faces > 0 ? global->layout_faces : s.estimated_faces;
  JsonWriter j;
  j.begin_object()
      .value("command", "surface")
      .value("base", base)
      .value("swatch", swatch)
      .value("method", method)
      .value("device", device)
      .value("threads", threads)
      .value("wall_seconds", wall);
  write_preparation(j, s);
  write_shell_map(j, em, embedding);
  write_element_figures(j, s, em);
  j.value("coverage", em.coverage)
      .begin_object("memory")
      .value("estimated_faces", estimated_faces)
      .value("estimated_bytes", estimated_faces * kBytesPerOutputFace + kBaseBytes)
      .value("limit_bytes", memory_limit_bytes)
      .value("peak_bytes", static_cast<double>(peak_memory_bytes()))
      .value("huge_pages", huge_pages_on())
      .value("page_probe_small_us", page_probe().small_us)
      .value("page_probe_huge_us", page_probe().huge_us)
      .value("freed_memory_kept", freed_memory_kept())
      .end_object()
      .value("swatch_coverage", swatch_cover)
      .value("min_coverage", min_coverage);
  write_placement(j, em, embedding);
  j.value("matched_point_offsets", s.matched_point_offsets);
  write_match_counts(j, s.counts);
  if (global) write_global_layout(j, *global);
  write_structure(j, structure.output, &structure.swatch, &structure.comparison);
  write_structure_check(j, shortfalls);
  write_detail(j, detail, detail_share);
  j.begin_object("stage_seconds");
  for (const auto& [stage, seconds] : s.times.stages()) j.value(stage, seconds);
  for (const auto& [stage, seconds] : em.times.stages()) j.value(stage, seconds);
  j.end_object().end_object();
  return j.str();
}

// The command's options (declared once, read by parse_surface_request).
void declare_surface_options(CommandLine& cl) {
  cl.option("base", "FILE", "base mesh (OBJ, PLY or OFF)");
  cl.option("swatch", "FILE", "swatch mesh; its smallest bounding-box side is the shell height");
  cl.option("output", "FILE", "output mesh (.obj, .ply, .off or .glb; not needed with --estimate)");
  cl.option("scale", "S", "swatch's longer side as a fraction of the base's bounding-box diagonal",
            "0.1");
  cl.option("element-size", "L",
            "instead of --scale: the swatch's longer side in the base's units, whatever the "
            "base's extent");
  cl.option("mask", "FILE",
            "quilt only where the mask is set: one weight in [0, 1] per base vertex (set where "
            ">= 0.5), or a first line 'faces' and then one 0-based face index per line; '#' "
            "lines are comments. Whole elements are kept or dropped (by where most of their "
            "vertices lie); coverage is judged over the mask");
  cl.option("size-map", "FILE",
            "vary the element size: one factor per base vertex (1: the size --scale or "
            "--element-size sets; the largest at most 8 times the smallest), followed by every "
            "method (a swatch animation moves each element at its size)");
  cl.option("field", "X Y Z", "guidance: a constant world direction projected on the surface", "",
            3);
  cl.option("field-file", "FILE", "guidance: one 'x y z' vector per base vertex");
  cl.option("keys", "FILE", "guidance: 'vertex x y z' key vectors diffused over the surface");
  cl.option("seed", "N", "random seed (used with --variety)", "1");
  cl.option("variety", "EPS", "choose randomly among offsets within (1+EPS) of the best", "0");
  cl.option("device", "auto|cpu|opencl",
            "where large translation-cost evaluations run (small ones stay on the CPU)", "auto");
  cl.flag("no-deform", "skip element deformation (section 2.6)");
  cl.flag("no-stretch-opt", "skip the shell map's stretch minimisation (on by default)");
  cl.option("embedding", "shell|normal",
            "place the texture through the shell map or by plain normal displacement", "shell");
  cl.flag("keep-intersecting", "keep elements that intersect others after embedding");
  cl.option("min-coverage", "F",
            "fail (exit 1, nothing written) when the base is covered less than this fraction of "
            "what the swatch covers of its own footprint (covered: texture within 1.5 shell "
            "heights on the base's outer side); 0 accepts any result",
            "0.9");
  cl.flag("keep-orientation",
          "grow the texture along the base's normals as given, even where they face inward");
  cl.flag("no-proxy",
          "use a base of over 200,000 faces as given (by default it is first simplified to the "
          "texture's scale, within 5% of the shell height)");
  cl.option("method", "auto|global|patches|vines",
            "global: one field-aligned parameterisation, seamless for a periodic swatch (keeps "
            "chain mail linked); patches: local conformal patches (the paper's); vines: stems "
            "grown along the field (up +Y without --field), evenly spaced, with the swatch's "
            "leaves along them; auto: global for a lattice of compact elements, vines for a vine "
            "with elements attached along it (ivy)",
            "auto");
  cl.option("element-placement", "adaptive|layout|rigid",
            "global layout: how a lattice element reaches the surface. layout: through the "
            "layout (keeps every link, takes its distortion); rigid: an even copy bent only by "
            "the surface; adaptive: through the layout where that keeps the element's shape, an "
            "even copy elsewhere",
            "adaptive");
  cl.flag(
      "estimate",
      "print the job's size and stop, writing nothing: one line 'estimate faces N bytes B "
      "seconds T fits 0|1'. N is the global layout's count of copies (within 10% of the "
      "faces written), the vines' stems at their spacing (within 10% on the sample ivy), or for "
      "the patches whole swatch copies over the area (apples: within 10%; sheets the patches "
      "cut: up to 2x over); T is rough (4 us a face on 2 cores, plus 0.5 s); fits: within "
      "--max-faces and --max-memory");
  cl.option("save-quilt", "FILE",
            "also save the result in local coordinates over the base (elements, their kinds, "
            "the embedding's options; docs/saved-quilt.md), for 'meshquilt embed' to place it "
            "again on the base moved (posed, animated) without a new synthesis");
  cl.option("swatch-frames", "PATTERN",
            "animate the result with the swatch (any method: ivy, chain mail, weave, apples): "
            "frames of the swatch, the same mesh with its vertices moved, named by a pattern with "
            "one frame number (%d or %0Nd; "
            "'meshquilt swatch ivy --frames N' makes some). Each output vertex moves as the point "
            "of the swatch it came from, in its own frame on the base; with --frames A-B, -o is a "
            "pattern too and one output is written per frame (same faces and element order)");
  cl.option("frames", "A-B", "the frames of --swatch-frames to follow, one output each");
  add_detail_option(cl);
  add_output_options(cl);
  add_run_options(cl);
}

// What the command line asks, checked before any work: usage errors (exit 2) and unwritable
// output paths (exit 1) come before a file is read.
struct SurfaceRequest {
  std::string out_path;
  WriteOptions write_options;
  SurfaceQuiltingOptions options;
  QuiltEmbeddingOptions embedding;
  std::string embedding_name;  // shell | normal
  std::string method;          // auto | global | patches | vines
  double min_coverage = 0;
  double detail = 1;
  Device device = Device::Auto;
  std::vector<SwatchFrame> frames;  // with --swatch-frames
};

SurfaceRequest parse_surface_request(const CommandLine& cl) {
  if (!cl.has("base")) throw UsageError("--base FILE is required");
  if (!cl.has("swatch")) throw UsageError("--swatch FILE is required");
  // --estimate writes nothing, so it needs no output name.
  if (!cl.has("output") && !cl.has("estimate")) throw UsageError("-o OUT is required");
  if (cl.has("field") + cl.has("field-file") + cl.has("keys") > 1)
    throw UsageError("give at most one of --field, --field-file and --keys");
  SurfaceRequest r;
  r.frames = requested_swatch_frames(cl);
  r.out_path = r.frames.empty() ? cl.get("output") : r.frames.front().output;
  r.write_options = output_options(cl);
  std::vector<std::string> outputs, inputs{cl.get("base"), cl.get("swatch"), cl.get("field-file"),
                                           cl.get("keys"), cl.get("mask")};
  for (const SwatchFrame& f : r.frames) inputs.push_back(f.swatch);
  for (const std::string& out : r.frames.empty() && !r.out_path.empty()
                                    ? std::vector<std::string>{r.out_path}
                                    : std::vector<std::string>{}) {
    mesh_format_from_path(out);
    for (const std::string& file : output_files(out, r.write_options)) outputs.push_back(file);
  }
  for (const SwatchFrame& f : r.frames) {
    mesh_format_from_path(f.output);
    for (const std::string& file : output_files(f.output, r.write_options)) outputs.push_back(file);
  }
  outputs.push_back(cl.get("stats"));
  outputs.push_back(cl.get("save-quilt"));
  check_paths(outputs, inputs);
  if (cl.has("scale") && cl.has("element-size"))
    throw UsageError("give --scale or --element-size, not both");

  SurfaceQuiltingOptions& options = r.options;
  options.scale = cl.get_double("scale", 0, 1e-6, 10.0);
  if (cl.has("element-size")) options.element_size = cl.get_double("element-size", 0, 1e-300);
  options.seed = static_cast<uint64_t>(cl.get_int("seed", 0, (1LL << 62)));
  options.matching.epsilon = cl.get_double("variety", 0, 0.0, 10.0);
  options.patch.deform = !cl.has("no-deform");
  options.orient_outward = !cl.has("keep-orientation");
  if (cl.has("no-proxy")) options.proxy_min_faces = 0;
  QuiltEmbeddingOptions& embedding = r.embedding;
  r.embedding_name = cl.get("embedding");
  if (r.embedding_name != "shell" && r.embedding_name != "normal")
    throw UsageError("--embedding expects shell or normal, got '" + r.embedding_name + "'");
  embedding.shell_map = r.embedding_name == "shell";
  embedding.optimize_stretch = !cl.has("no-stretch-opt");
  embedding.remove_intersecting = !cl.has("keep-intersecting");
  embedding.seed = options.seed;
  r.min_coverage = cl.get_double("min-coverage", 0, 0.0, 1.0);
  r.detail = detail_share(cl);
  options.global.drop_folded_pieces = !embedding.shell_map;
  options.max_faces = face_limit(cl);
  r.device = parse_device(cl.get("device"));
  const std::string placement = cl.get("element-placement");
  if (placement == "layout")
    options.global.placement = SurfaceQuiltingOptions::Global::Placement::kLayout;
  else if (placement == "rigid")
    options.global.placement = SurfaceQuiltingOptions::Global::Placement::kRigid;
  else if (placement != "adaptive")
    throw UsageError("--element-placement expects adaptive, layout or rigid, got '" + placement +
                     "'");
  options.keep_sources = !r.frames.empty();
  r.method = cl.get("method");
  if (r.method != "auto" && r.method != "global" && r.method != "patches" && r.method != "vines")
    throw UsageError("--method expects auto, global, patches or vines, got '" + r.method + "'");
  return r;
}

// The inputs, read and checked against the request (sizes relative to the base); the guidance
// field goes into r.options.
struct SurfaceInputs {
  TriMesh base;
  ElementDetail swatch;                // at --detail (its mesh is the swatch quilted)
  TriMesh full_swatch;                 // as read
  SurfaceMask mask;                    // empty without --mask
  std::vector<TriMesh> swatch_frames;  // with --swatch-frames: each frame as read
};

void read_surface_inputs(const CommandLine& cl, SurfaceRequest& r, SurfaceInputs& in) {
  SurfaceQuiltingOptions& options = r.options;
  in.base = read_mesh(cl.get("base"));
  in.swatch = read_swatch(cl.get("swatch"), r.detail, &in.full_swatch);
  const TriMesh &base = in.base, &swatch = in.swatch.mesh;
  // Finite coordinates whose extent overflows (1e300) would make every size estimate NaN.
  for (const auto& [mesh, name] :
       {std::pair<const TriMesh*, std::string>{&base, cl.get("base")}, {&swatch, cl.get("swatch")}})
    MQ_CHECK(mesh->num_vertices() == 0 ||
                 std::isfinite(
                     (mesh->V.colwise().maxCoeff() - mesh->V.colwise().minCoeff()).squaredNorm()),
             InvalidInput, name,
             ": coordinates too large (the bounding box's diagonal overflows); scale the mesh "
             "down");
  // The swatch's thickness is the shell's height (section 3.2): a flat swatch has none.
  if (swatch.num_vertices() > 0) {
    const Vector3d extent = swatch.V.colwise().maxCoeff() - swatch.V.colwise().minCoeff();
    MQ_CHECK(extent.minCoeff() > 1e-9 * extent.maxCoeff(), InvalidInput, cl.get("swatch"),
             ": the swatch is flat (no thickness along its smallest side), and surface grows it "
             "in a shell as thick as the swatch; give it thickness, or use plane");
  }
  // --scale's range, relative to the base's diagonal.
  const double diagonal = base.num_vertices() ? bounding_box(base.V).extent().norm() : 0.0;
  if (options.element_size > 0 && diagonal > 0 &&
      !(options.element_size >= 1e-6 * diagonal && options.element_size <= 10 * diagonal))
    throw UsageError("--element-size must be in [1e-6, 10] times the base's diagonal " +
                     std::to_string(diagonal));
  // Every swatch frame read and checked before any work: a missing frame, or one that is not the
  // swatch moved, fails the run before anything is written.
  for (const SwatchFrame& f : r.frames) {
    in.swatch_frames.push_back(read_mesh(f.swatch));
    check_swatch_frame(swatch, in.swatch_frames.back(), f.swatch);
  }
  if (cl.has("mask")) {
    in.mask = read_surface_mask(cl.get("mask"), base);
    // Vines grow within the mask (their long stems stop at its border); the other methods'
    // elements are dropped whole outside it after the synthesis.
    options.region = [&in](const TriMesh& refined) {
      return mask_faces(in.mask, in.base, refined);
    };
  }
  if (cl.has("size-map")) options.size_map = read_size_map(cl.get("size-map"), base);
  if (cl.has("field")) {
    const Vector3d d(cl.get_double("field", 0), cl.get_double("field", 1),
                     cl.get_double("field", 2));
    if (!(d.norm() > 0)) throw UsageError("--field needs a non-zero direction");
    options.field = tangent_field_from_direction(base.V, base.F, d);
  } else if (cl.has("field-file")) {
    options.field = tangent_field_from_vertex_vectors(
        base.V, base.F, read_vertex_vector_field(cl.get("field-file"), base.num_vertices()));
  } else if (cl.has("keys")) {
    options.field = tangent_field_from_key_vectors(
        base.V, base.F, read_key_vectors(cl.get("keys"), base.num_vertices()));
  }
}

// --estimate: the job's size before any synthesis, one line (issue 26: the add-on shows it
// before Run).
void print_estimate(const CommandLine& cl, const SurfaceRequest& r, const SurfaceInputs& in) {
  const TriMesh &base = in.base, &swatch = in.swatch.mesh;
  // The size before any synthesis (issue 26: the add-on shows it before Run): the method's
  // own count, as the run checks it against --max-faces (the global layout's lattice copies,
  // within 5% of the faces written on the gallery's chain mail; the vines' stems at their
  // spacing, within 6% on the ivy wall, David and Spot; the preparation's for the patches).
  SurfaceQuiltingOptions counting = r.options;
  counting.max_faces = std::numeric_limits<double>::infinity();
  counting.global.count_only = true;
  TranslationCostCpu cpu;
  SurfaceQuiltingStats estimate;
  GlobalQuiltingStats layout;
  bool global = r.method == "global", vines = r.method == "vines";
  if (r.method == "auto")
    quilt_surface_auto(base, swatch, counting, cpu, &estimate, &layout, nullptr, &global, &vines);
  else if (global)
    quilt_surface_global(base, swatch, counting, cpu, &estimate, &layout);
  else if (vines)
    quilt_surface_vines(base, swatch, counting, {}, &estimate);
  else
    prepare_surface_job(base, swatch, counting, estimate);
  // Under a mask only the masked part is kept (whole elements, about as many as its area).
  const double faces =
      (global && layout.layout_faces > 0 ? layout.layout_faces : estimate.estimated_faces) *
      (cl.has("mask") ? masked_area_share(in.mask, base) : 1.0);
  const double bytes = faces * kBytesPerOutputFace + kBaseBytes;
  const double limit = memory_limit(cl);
  const bool fits = faces <= r.options.max_faces && (!(limit > 0) || bytes <= limit);
  std::printf("estimate faces %.0f bytes %.0f seconds %.1f fits %d\n", faces, bytes,
              0.5 + 4e-6 * faces, fits ? 1 : 0);
}

// What a run made, for the summary and the --stats file.
struct SurfaceOutcome {
  SurfaceQuiltingStats stats;
  GlobalQuiltingStats global_stats;
  VineGrowthStats vine_stats;
  QuiltEmbeddingStats embedding;
  bool global = false, vines = false;  // the method run (auto decides)
  StructureSummary structure;
  std::vector<StructureShortfall> shortfalls;  // the structure's figures outside their limits
  SettledMotionStats settled;                  // with --swatch-frames
  double wall = 0;
};

// The synthesis by the method asked (auto decides, and says which in `o`).
SurfaceQuilt quilt_by_method(const SurfaceRequest& r, const SurfaceInputs& in,
                             TranslationCostEvaluator& evaluator, ProgressSink* progress,
                             SurfaceOutcome& o) {
  const TriMesh &base = in.base, &swatch = in.swatch.mesh;
  o.global = r.method == "global";
  o.vines = r.method == "vines";
  if (r.method == "auto")
    return quilt_surface_auto(base, swatch, r.options, evaluator, &o.stats, &o.global_stats,
                              progress, &o.global, &o.vines, &o.vine_stats);
  if (o.global)
    return quilt_surface_global(base, swatch, r.options, evaluator, &o.stats, &o.global_stats,
                                progress);
  if (o.vines)
    return quilt_surface_vines(base, swatch, r.options, {}, &o.stats, &o.vine_stats, progress);
  return quilt_surface(base, swatch, r.options, evaluator, &o.stats, progress);
}

// The saved quilt (issue 25): the output in prism coordinates over the base.
SavedQuilt make_saved(const CommandLine& cl, const SurfaceRequest& r, const SurfaceInputs& in,
                      const SurfaceQuilt& quilt, const TriMesh& result) {
  SavedQuiltHeader header;
  header.base = fingerprint(in.base);
  header.origin = "surface --swatch " + cl.get("swatch") + " --method " + r.method +
                  (cl.has("element-size") ? " --element-size " + cl.get("element-size")
                                          : " --scale " + cl.get("scale")) +
                  (cl.has("mask") ? " --mask " + cl.get("mask") : std::string()) +
                  (r.detail < 1 ? " --detail " + cl.get("detail") : std::string()) + " --seed " +
                  cl.get("seed");
  return make_saved_quilt(quilt, result, header);
}

// The structure figures (issue 13) and the run's own check of them (issue 23: a result that
// lost the swatch's structure is never reported as a plain success), on every run: 5-9% of the
// Table 1 jobs' time (0.57 s of the armor's 6.5 s). Returns the seconds taken (not part of
// the run's wall time).
// Under a mask the textured surface is the masked faces: its border is where rings end by
// design (else the rings along it would count as interior rings missing links).
double measure_structure(const TriMesh& result, const SurfaceInputs& in, const SurfaceQuilt& quilt,
                         const std::vector<char>& masked, SurfaceOutcome& o) {
  const auto t0 = std::chrono::steady_clock::now();
  ScopedStageTimer timer(o.stats.times, Stage::Structure);
  std::optional<TriMesh> textured;
  if (!masked.empty()) {
    std::vector<int> faces;
    for (int f = 0; f < static_cast<int>(masked.size()); ++f)
      if (masked[static_cast<size_t>(f)]) faces.push_back(f);
    textured = extract_faces(quilt.base, faces);
  }
  o.structure = summarize_structure(result, in.swatch.mesh, textured ? &*textured : &in.base,
                                    o.stats.swatch_scale);
  o.shortfalls = check_structure(o.structure);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// What to try when the check finds the structure lost: the local patches cut a periodic
// swatch where they meet, the global layout does not; elsewhere, elements pressed together
// between cones and over creases get more room at a smaller size. A sheet of rings in which no
// lattice was found repeating (a 2 x 2 chain mail sheet: auto quilts it by patches, 10.7% of
// rings linked on a cube; --method global only quilts the parameter plane, 45.3%) needs a
// larger sheet, and a swatch of other elements the patches take by design needs more of them.
std::string structure_hint(const SurfaceRequest& r, const SurfaceOutcome& o) {
  if (o.vines || (o.global && o.global_stats.periodic))
    return "a smaller --scale gives each element more room";
  if (r.method == "patches") return "--method global lays a periodic swatch out whole";
  if (o.structure.swatch.ring_kinds() > 0)
    return "no lattice repeats in the swatch; a sheet of two periods or more each way lets the "
           "layout repeat it whole";
  return "a swatch of more elements gives the patches more to match";
}

// --swatch-frames: the result's vertices located in the swatch and the frames' motions, settled
// so that no element meets another in any frame.
SwatchAnimation animate(const SurfaceRequest& r, const SurfaceInputs& in, const SurfaceQuilt& quilt,
                        const TriMesh& result, SurfaceOutcome& o,
                        std::vector<SwatchMotion>& motions) {
  ScopedStageTimer timer(o.stats.times, Stage::Animation);
  SwatchAnimation animation(quilt, o.embedding.kept, result, in.swatch.mesh, o.stats.swatch_scale);
  for (size_t k = 0; k < r.frames.size(); ++k)
    motions.push_back(swatch_motion(in.swatch.mesh, in.swatch_frames[k], o.stats.swatch_scale,
                                    r.frames[k].swatch));
  animation.settle(motions, &o.settled);
  return animation;
}

// Every method keeps the sources when asked (SurfaceQuiltingOptions::keep_sources, issue 25):
// an element without them is a fault of ours, found before the embedding.
void check_sources(const SurfaceRequest& r, const SurfaceQuilt& quilt) {
  const bool sourced =
      std::all_of(quilt.elements.begin(), quilt.elements.end(), [](const SurfaceElement& e) {
        return e.source.rows() == static_cast<Eigen::Index>(e.face.size());
      });
  MQ_CHECK(r.frames.empty() || sourced, InternalError,
           "--swatch-frames: the result's elements do not say where in the swatch they come from");
}

// The summary a run prints unless --quiet (the structure follows with --stats).
void print_surface_summary(const SurfaceRequest& r, const SurfaceInputs& in,
                           const SurfaceOutcome& o, const std::string& device, int threads) {
  const SurfaceQuiltingStats& stats = o.stats;
  const GlobalQuiltingStats& gstats = o.global_stats;
  const VineGrowthStats& vstats = o.vine_stats;
  const QuiltEmbeddingStats& e = o.embedding;
  const bool global = o.global, vines = o.vines;
  print_detail(in.swatch, r.detail);
  std::printf(
      "wrote %s: %d faces, %d vertices, %d elements (shell height %.4g), %.1f%% of the base "
      "covered\n",
      r.out_path.c_str(), e.faces, e.vertices, e.elements, stats.shell_height, 100.0 * e.coverage);
  // Faces meeting three or more at an edge (fins, flaps): the layout ends there as at a
  // border, which the user should know of rather than find (issue 28, item 7).
  if (stats.fin_faces > 0)
    std::printf(
        "base: %d faces in fins (pieces sticking out at non-manifold edges, %.2g%% of the "
        "area) were left out: the texture covers the surface they stand on\n",
        stats.fin_faces, 100.0 * stats.fin_area_share);
  if (stats.sheet_back_faces > 0)
    std::printf(
        "base: two-sided (each face listed again facing the other way, enclosing nothing): its "
        "%d backs were left out, the texture grows on the side listed first\n",
        stats.sheet_back_faces);
  if (stats.non_manifold_edges > 0)
    std::printf(
        "base: %d non-manifold edges (three or more faces meeting) are borders: the "
        "texture ends at them on every side\n",
        stats.non_manifold_edges);
  if (stats.flipped_components > 0)
    std::printf(
        "base: %d components faced inward and were turned outward "
        "(--keep-orientation keeps them)\n",
        stats.flipped_components);
  if (stats.proxy_faces > 0)
    std::printf(
        "base: simplified to %d faces, within %.3g of the surface given "
        "(--no-proxy keeps it)\n",
        stats.proxy_faces, stats.proxy_error);
  if (!e.shell_map_failure.empty())
    std::printf("shell map unavailable (%s): placed by normal displacement\n",
                e.shell_map_failure.c_str());
  else if (r.embedding.shell_map)
    std::printf("shell map: L2 stretch %.4f -> %.4f (%d charts)\n", e.stretch_before,
                e.stretch_after, e.atlas_charts);
  if (e.shell_map_failure.empty() && e.fallback_faces > 0)
    std::printf(
        "shell map left out %d base faces (%.1f%% of the area; %s): %d elements "
        "placed over them by normal displacement\n",
        e.fallback_faces, 100 * e.fallback_area_share, e.fallback_reason.c_str(),
        e.fallback_elements);
  std::printf(
      "placement: %.2f%% of vertices under the base (%.2f%% as embedded; elements "
      "under it: %d placed again by normal displacement, %d lifted, %d removed), "
      "%.2f%% above the shell\n",
      100 * e.below_base, 100 * e.below_base_embedded, e.replaced_below, e.lifted_below,
      e.removed_below, 100 * e.above_shell);
  if (global)
    std::printf(
        "global parameterisation: %d cones, %d cut edges%s; %s plane texture, %d elements "
        "placed (%d off the surface)\n",
        gstats.singular_vertices, gstats.cut_edges, gstats.seamless ? ", seamless" : "",
        gstats.tiled ? "tiled" : "quilted", gstats.placed, gstats.off_surface);
  if (!r.frames.empty()) print_swatch_animation(r.frames, o.settled);
  if (vines)
    std::printf(
        "%d stems (spacing %.4g, median %.2f swatch vines long; %d cut where they would "
        "intersect, %d pieces and %d short lines left out), %d of %d leaves placed (%d moved "
        "along the stem), %.2f s on %d threads; %d removed (%d folded)\n",
        vstats.stems, vstats.spacing, vstats.median_length, vstats.stems_cut, vstats.stems_dropped,
        vstats.streamlines_short, vstats.leaves, vstats.leaf_slots, vstats.leaves_shifted, o.wall,
        threads, e.removed_intersecting + e.removed_self_intersecting, e.removed_self_intersecting);
  else if (global && gstats.tiled)
    std::printf(
        "%.2f s on %s (%d threads); %d folded elements repaired, %d of %d rings folded over an "
        "edge hung over it, %d removed\n",
        o.wall, device.c_str(), threads, e.rigid_repairs, e.unbent_rings, e.folded_rings,
        e.removed_intersecting + e.removed_self_intersecting);
  else
    std::printf(
        "%d %s in %.2f s on %s (%d threads); elements: %d stitched, %d replaced, "
        "%d added, %d matched, %d removed (%d folded)\n",
        stats.iterations, global ? "plane iterations" : "patches", o.wall, device.c_str(), threads,
        stats.counts.stitched, stats.counts.replaced, stats.counts.added, stats.counts.matched,
        e.removed_intersecting + e.removed_self_intersecting, e.removed_self_intersecting);
}

}  // namespace

int run_surface(int argc, char** argv, int first) {
  CommandLine cl("surface", "--base BASE --swatch SW -o OUT [options]",
                 "Covers a base mesh (closed or with boundary, any genus, several components)\n"
                 "with the swatch's geometry inside a thin shell over its surface, by mesh\n"
                 "quilting over local conformal patches (paper section 3.1).");
  declare_surface_options(cl);
  if (!cl.parse(argc, argv, first)) return 0;
  SurfaceRequest r = parse_surface_request(cl);
  RunContext run(cl);
  const auto start = std::chrono::steady_clock::now();
  SurfaceInputs in;
  read_surface_inputs(cl, r, in);
  if (r.detail < 1) r.options.full_detail_swatch = &in.full_swatch;
  if (cl.has("estimate")) {
    print_estimate(cl, r, in);
    return 0;
  }
  std::unique_ptr<TranslationCostEvaluator> evaluator = make_translation_cost_evaluator(r.device);
  SurfaceOutcome o;
  SurfaceQuilt quilt = quilt_by_method(r, in, *evaluator, run.progress(), o);
  check_sources(r, quilt);
  if (cl.has("mask")) {
    r.embedding.coverage_faces = mask_quilt_faces(in.mask, in.base, quilt);
    drop_unmasked_elements(quilt, r.embedding.coverage_faces);
  }
  std::unique_ptr<TetStretchEvaluator> stretch = make_tet_stretch_evaluator(r.device);
  const TriMesh result = embed_quilt(quilt, r.embedding, *stretch, &o.embedding, run.progress());
  // A run that makes no geometry is an error, not an empty file (issue 14).
  MQ_CHECK(!quilt.elements.empty(), InvalidInput,
           "no element of the swatch could be placed on the base at ", size_option(r.options),
           " (is the swatch larger than the base?); nothing written");
  // No silent wrong result (issue 23): a result that leaves the base bare fails, naming the
  // likely cause.
  const TriMesh& swatch = in.swatch.mesh;
  const double own_coverage = swatch_coverage(swatch);
  check_embedded_result(static_cast<int>(quilt.elements.size()), result, o.embedding,
                        r.min_coverage, own_coverage, "try a smaller --scale");
  SavedQuilt saved;
  if (cl.has("save-quilt")) {
    ScopedStageTimer timer(o.stats.times, Stage::SaveQuilt);
    saved = make_saved(cl, r, in, quilt, result);
  }
  const double measuring = measure_structure(result, in, quilt, r.embedding.coverage_faces, o);
  if (cl.has("save-quilt")) write_saved_quilt(cl.get("save-quilt"), saved);
  // The mesh and the --stats file are one commit (issue 28); with --swatch-frames the mesh is
  // the first frame's, and the others follow.
  std::optional<SwatchAnimation> animation;
  std::vector<SwatchMotion> motions;
  if (!r.frames.empty()) animation = animate(r, in, quilt, result, o, motions);
  const auto frame = [&](size_t k) { return animation->frame(motions[k]); };
  o.wall = write_output_and_stats(
      run, r.out_path, animation ? frame(0) : result, r.write_options, o.stats.times, start,
      measuring, [&](double w) {
        return stats_json(o.stats, o.embedding, r.embedding_name, evaluator->name(), run.threads(),
                          w, cl.get("base"), cl.get("swatch"),
                          o.global  ? "global"
                          : o.vines ? "vines"
                                    : "patches",
                          o.global ? &o.global_stats : nullptr, o.structure, o.shortfalls,
                          memory_limit(cl), r.min_coverage, own_coverage, in.swatch, r.detail);
      });
  for (size_t k = 1; k < r.frames.size(); ++k) {
    ScopedStageProgress shown(run.progress(), Stage::Writing);
    write_output(r.frames[k].output, frame(k), r.write_options);
  }
  run.progress()->finish();
  if (!run.quiet()) {
    print_surface_summary(r, in, o, evaluator->name(), run.threads());
    print_run_structure(o.structure, !run.stats_path().empty());
  }
  warn_structure("surface", o.shortfalls, structure_hint(r, o));
  return 0;
}

}  // namespace mq::cli
