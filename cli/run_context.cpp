#include "cli/run_context.h"

#include <sys/resource.h>
#include <tbb/info.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/common/errors.h"
#include "core/common/progress.h"

namespace mq::cli {

void print_swatch_animation(const std::vector<SwatchFrame>& frames,
                            const SettledMotionStats& settled) {
  std::printf(
      "swatch animation: %zu frames (to %s); %d elements move at half their motion and %d "
      "stay still, where they would meet another element",
      frames.size(), frames.back().output.c_str(), settled.damped, settled.stilled);
  if (settled.faded > 0)
    std::printf("; %d threads slow down near where they would meet", settled.faded);
  std::printf("\n");
}

std::vector<SwatchFrame> requested_swatch_frames(const CommandLine& cl) {
  if (cl.has("swatch-frames") != cl.has("frames"))
    throw UsageError("--swatch-frames and --frames A-B go together");
  std::vector<SwatchFrame> frames;
  if (!cl.has("frames")) return frames;
  if (cl.has("detail") && cl.get_double("detail", 0) != 1)
    throw UsageError("--swatch-frames animates the swatch as given: not with --detail");
  const auto [a, b] = frame_range(cl.get("frames"));
  const FramePattern swatch(cl.get("swatch-frames"), "--swatch-frames"),
      output(cl.get("output"), "-o");
  for (int f = a; f <= b; ++f) frames.push_back({f, swatch(f), output(f)});
  return frames;
}

Device parse_device(const std::string& name) {
  if (name == "auto") return Device::Auto;
  if (name == "cpu") return Device::Cpu;
  if (name == "opencl") return Device::OpenCL;
  throw UsageError("--device expects auto, cpu or opencl, got '" + name + "'");
}

void add_run_options(CommandLine& cl) {
  cl.flag("quiet", "print nothing but errors (no progress, no summary)");
  cl.option("stats", "FILE.json", "write counts and per-stage timings as JSON");
  cl.option("threads", "N", "worker threads (0 = all cores)", "0");
  cl.flag("progress-lines",
          "progress as 'progress STAGE FRACTION ELAPSED_S REMAINING_S' lines (for other programs)");
  cl.option("max-faces", "N",
            "refuse a job estimated to output more faces (also bounded by the memory limit)",
            "2e7");
  cl.option("max-memory", "GIB",
            "refuse a job estimated to need more memory, at about 400 bytes per output face "
            "(default: 80% of the machine's memory)");
}

void add_detail_option(CommandLine& cl) {
  cl.option("detail", "F",
            "share of each swatch element's faces to keep, in (0, 1]: each element simplified "
            "on its own (rings keep their holes, links and bounding boxes); 0.1 makes a preview "
            "5-7x faster",
            "1");
}

double detail_share(const CommandLine& cl) { return cl.get_double("detail", 0, 1e-3, 1.0); }

ElementDetail read_swatch(const std::string& path, double share, TriMesh* full) {
  ElementDetailOptions options;
  options.detail = share;
  TriMesh swatch = read_mesh(path);
  ElementDetail detail = reduce_element_detail(swatch, options);
  if (full && share < 1) *full = std::move(swatch);  // the layout's, needed below full detail
  return detail;
}

void print_detail(const ElementDetail& detail, double share) {
  if (share < 1)
    std::printf(
        "swatch at detail %.3g: %d elements (%d distinct, %d kept finer so that nothing "
        "intersects), median %d -> %d faces (largest %d -> %d)\n",
        share, detail.elements, detail.groups, detail.raised, detail.median_faces_before,
        detail.median_faces_after, detail.max_faces_before, detail.max_faces_after);
}

void write_detail(JsonWriter& j, const ElementDetail& detail, double share) {
  j.begin_object("swatch_detail")
      .value("share", share)
      .value("elements", detail.elements)
      .value("distinct_elements", detail.groups)
      .value("kept_finer", detail.raised)
      .value("median_faces_before", detail.median_faces_before)
      .value("median_faces_after", detail.median_faces_after)
      .value("max_faces_before", detail.max_faces_before)
      .value("max_faces_after", detail.max_faces_after)
      .end_object();
}

void add_output_options(CommandLine& cl) {
  cl.option("groups", "element|kind|none",
            "OBJ output: one object per element (KIND_ID), one per kind, or none", "element");
  cl.flag("no-normals", "write no normals (flat shading in viewers)");
}

WriteOptions output_options(const CommandLine& cl) {
  WriteOptions o;
  o.write_elements = true;
  o.write_normals = !cl.has("no-normals");
  const std::string g = cl.get("groups");
  if (g == "element")
    o.groups = ElementGroups::Element;
  else if (g == "kind")
    o.groups = ElementGroups::Kind;
  else if (g == "none")
    o.groups = ElementGroups::None;
  else
    throw UsageError("--groups expects element, kind or none, got '" + g + "'");
  return o;
}

std::vector<std::string> output_files(const std::string& path, const WriteOptions& options) {
  std::vector<std::string> files{path};
  if (options.write_elements && mesh_format_from_path(path) == MeshFormat::Obj)
    files.push_back(std::filesystem::path(path).replace_extension(".mtl").string());
  return files;
}

void write_output(const std::string& path, TriMesh mesh, const WriteOptions& options) {
  mesh.N.resize(0, 3);
  write_mesh(path, mesh, options);
}

double write_output_and_stats(RunContext& run, const std::string& path, const TriMesh& mesh,
                              const WriteOptions& options, StageTimes& times,
                              std::chrono::steady_clock::time_point start, double excluded,
                              const std::function<std::string(double wall)>& stats_json) {
  ScopedStageProgress shown(run.progress(), Stage::Writing);
  const auto write_start = std::chrono::steady_clock::now();
  double wall = 0;
  const auto finish_timing = [&] {
    const auto now = std::chrono::steady_clock::now();
    times.add(Stage::Writing, std::chrono::duration<double>(now - write_start).count());
    wall = std::chrono::duration<double>(now - start).count() - excluded;
  };
  WriteOptions with_stats = options;
  if (!run.stats_path().empty()) {
    with_stats.companion_path = run.stats_path();
    with_stats.companion_bytes = [&] {
      finish_timing();
      return stats_json(wall);
    };
  }
  write_output(path, mesh, with_stats);
  if (run.stats_path().empty()) finish_timing();
  return wall;
}

double memory_limit(const CommandLine& cl) {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  const double machine =
      pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
  if (cl.has("max-memory")) {
    const double asked = cl.get_double("max-memory", 0, 0.01, 1e6) * (1 << 30);
    MQ_CHECK(machine == 0 || asked <= machine, InvalidInput, "--max-memory ", asked / (1 << 30),
             " GiB is more than this machine's ", machine / (1 << 30), " GiB");
    return asked;
  }
  return machine > 0 ? 0.8 * machine : 0.0;
}

double face_limit(const CommandLine& cl) {
  const double asked = cl.get_double("max-faces", 0, 1, 1e12);
  const double memory = memory_limit(cl);
  if (!(memory > 0)) return asked;
  const double fits = memory / kBytesPerOutputFace;
  MQ_CHECK(asked <= fits || !cl.has("max-faces"), InvalidInput, "--max-faces ", asked,
           " needs about ", asked * kBytesPerOutputFace / (1 << 30),
           " GiB of memory; the limit is ", memory / (1 << 30), " GiB (--max-memory)");
  return std::min(asked, fits);
}

long peak_memory_bytes() {
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<long>(usage.ru_maxrss) * 1024;  // kilobytes on Linux
}

void check_output_directory(const std::string& path) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  MQ_CHECK(dir.empty() || std::filesystem::is_directory(dir, ec), InvalidInput, path,
           ": the directory '", dir.string(), "' does not exist");
}

namespace {

// Whether a and b name the same file: the same inode when both exist, else the same normalised
// absolute path.
bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return ca == cb;
}

}  // namespace

void check_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  for (size_t i = 0; i < outputs.size(); ++i) {
    const std::string& out = outputs[i];
    if (out.empty()) continue;
    // An OBJ names its .mtl by the output's name on one text line (mtllib), and --stats records
    // it in JSON: a name with a line break or another control character, or bytes that are not
    // UTF-8, would break them (issue 28).
    for (const char c : out)
      MQ_CHECK(static_cast<unsigned char>(c) >= 0x20 && c != 0x7f, InvalidInput,
               detail::printable(out),
               ": the output name contains a line break or another control character; choose "
               "another name");
    MQ_CHECK(detail::printable(out) == out, InvalidInput, detail::printable(out),
             ": the output name is not UTF-8 text; choose a name in UTF-8");
    check_output_directory(out);
    std::error_code ec;
    MQ_CHECK(!fs::is_directory(out, ec), InvalidInput, out, ": is a directory");
    const fs::path dir = fs::path(out).parent_path();
    MQ_CHECK(::access(dir.empty() ? "." : dir.c_str(), W_OK | X_OK) == 0, InvalidInput, out,
             ": cannot write in the directory '", dir.empty() ? "." : dir.string(), "'");
    for (size_t j = 0; j < i; ++j)
      MQ_CHECK(outputs[j].empty() || !same_file(out, outputs[j]), InvalidInput, out,
               ": named as two outputs (e.g. -o and --stats)");
    for (const std::string& in : inputs)
      MQ_CHECK(in.empty() || !same_file(out, in), InvalidInput, out,
               ": is also an input file; it would be overwritten");
  }
}

RunContext::RunContext(const CommandLine& cl)
    : quiet_(cl.has("quiet")),
      stats_path_(cl.get("stats")),
      threads_(static_cast<int>(cl.get_int("threads", 0, 1024))),
      progress_(quiet_, cl.has("progress-lines")) {
  if (!stats_path_.empty()) check_output_directory(stats_path_);
  if (threads_ > 0)
    control_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     static_cast<size_t>(threads_));
  else
    threads_ = tbb::info::default_concurrency();
}

}  // namespace mq::cli
