// Options every synthesis command shares: --quiet, --stats FILE.json, --threads N, --device.
#pragma once

#include <tbb/global_control.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/console_progress.h"
#include "cli/json_writer.h"
#include "core/common/stage_timer.h"
#include "core/mesh/element_detail.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/settled_motion.h"
#include "host/device.h"

namespace mq::cli {

// The --device choice ("auto", "cpu" or "opencl"); throws UsageError otherwise.
Device parse_device(const std::string& name);

// Declares the shared options on a command line.
void add_run_options(CommandLine& cl);

// Throws InvalidInput naming `path` when the directory it would be written to does not exist,
// so that a run fails before its work rather than after it (leaving nothing half done).
void check_output_directory(const std::string& path);

// Peak memory per output face, measured with a margin: the armor job 710 MiB for 2.2M faces
// (330 bytes), Blender's UV sphere with the sample mail at scale 0.1 2.0 GB for 6.4M (310).
inline constexpr double kBytesPerOutputFace = 400;
// The process's own before any output (libraries, the OpenCL runtime, the inputs): a 3k-face
// job peaks at 60-110 MiB.
inline constexpr double kBaseBytes = 128.0 * (1 << 20);

// The memory a job may take (--max-memory GiB, default 80% of the machine's), in bytes; 0 when
// unknown. Throws InvalidInput for more than the machine has.
double memory_limit(const CommandLine& cl);

// The --max-faces limit, lowered to what the memory limit holds at kBytesPerOutputFace. Throws
// InvalidInput when an explicit --max-faces cannot fit in it.
double face_limit(const CommandLine& cl);

// This process's peak resident memory so far, in bytes (0 when unknown).
long peak_memory_bytes();

// Every output path checked before any work (issue 14): its directory exists and is writable,
// it is not a directory, and it names neither another output nor an input file (`--stats
// out.obj -o out.obj` would replace the mesh with the JSON; `--stats` naming the swatch would
// overwrite an input). Empty paths are skipped. Throws InvalidInput naming the path.
void check_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

// --groups element|kind|none and --no-normals: what an output mesh carries (issue 15).
void add_output_options(CommandLine& cl);

// The write options of an output mesh: element ids and kinds (OBJ groups and materials, PLY
// properties, glTF attributes) and per-corner normals, unless --no-normals.
WriteOptions output_options(const CommandLine& cl);

// The files a result written to `path` consists of: path, and for an OBJ with elements its .mtl.
std::vector<std::string> output_files(const std::string& path, const WriteOptions& options);

// Writes a result mesh: its normals are computed per corner by the writer (write_mesh) rather
// than carried from the quilting (element normals would smooth over sharp edges).
void write_output(const std::string& path, TriMesh mesh, const WriteOptions& options);

// --detail F for the commands that grow a swatch: each element simplified to a share F of its
// faces (a fast Preview, or a lighter result; issue 26).
void add_detail_option(CommandLine& cl);

// --detail's value; throws UsageError outside (0, 1] (before any work).
double detail_share(const CommandLine& cl);

// The swatch at `path` at a share of its detail (core/mesh/element_detail.h), with the element
// counts before and after; `full` (optional) receives the swatch as read when share < 1. Throws as
// read_mesh and reduce_element_detail do.
ElementDetail read_swatch(const std::string& path, double share, TriMesh* full = nullptr);

// The detail's line of a run's summary (nothing at full detail) and its --stats entry.
void print_detail(const ElementDetail& detail, double share);
void write_detail(JsonWriter& j, const ElementDetail& detail, double share);

// With --swatch-frames PATTERN and --frames A-B (issue 25, swatch animation): per frame, its
// number, the swatch frame's file and the output's (-o a pattern too).
struct SwatchFrame {
  int number = 0;
  std::string swatch, output;
};

// The frames --swatch-frames and --frames ask for, or none. Throws UsageError when one comes
// without the other, with --detail below 1, or for a pattern without one frame number.
std::vector<SwatchFrame> requested_swatch_frames(const CommandLine& cl);

// The summary line of a swatch animation: the frames written and the elements damped.
void print_swatch_animation(const std::vector<SwatchFrame>& frames,
                            const SettledMotionStats& settled);

// Applies the shared options for the lifetime of the object: thread limit and progress sink.
class RunContext {
 public:
  // Throws InvalidInput when the --stats file's directory does not exist.
  explicit RunContext(const CommandLine& cl);
  ProgressSink* progress() { return &progress_; }
  bool quiet() const { return quiet_; }
  const std::string& stats_path() const { return stats_path_; }
  int threads() const { return threads_; }

 private:
  bool quiet_;
  std::string stats_path_;
  int threads_;
  std::unique_ptr<tbb::global_control> control_;
  ConsoleProgress progress_;
};

// Writes a result (write_output) and its --stats file, when the run asks for one, as one commit
// (issue 28): stats_json(wall) makes the stats once the mesh is written out, so that they hold
// the write's seconds (added to `times` as Stage::Writing) and the run's wall time: since `start`,
// less `excluded` (seconds spent on figures for the stats alone). Returns that wall time.
double write_output_and_stats(RunContext& run, const std::string& path, const TriMesh& mesh,
                              const WriteOptions& options, StageTimes& times,
                              std::chrono::steady_clock::time_point start, double excluded,
                              const std::function<std::string(double wall)>& stats_json);

}  // namespace mq::cli
