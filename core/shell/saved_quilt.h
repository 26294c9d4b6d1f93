// A saved quilt (issue 25; paper section 3.2: the output is kept in local coordinates over the
// base, so the base can be edited or animated without a new synthesis): a SurfaceQuilt with
// everything but the base's positions, the embedding options of its run and a fingerprint of the
// base's connectivity. `meshquilt surface --save-quilt` writes one, `meshquilt embed` places it
// on the base, moved or not, and re-embedding on the unchanged base gives the synthesis's output
// byte for byte. The format is documented in docs/saved-quilt.md.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/shell/quilt_embedding.h"
#include "core/surface/surface_quilting.h"

namespace mq {

// What a base must keep for a quilt to follow it: its vertex and face counts and its faces.
struct BaseFingerprint {
  std::int64_t vertices = 0, faces = 0;
  std::uint64_t connectivity = 0;  // FNV-1a 64 of F, row by row, as 32-bit little-endian
  bool operator==(const BaseFingerprint& o) const {
    return vertices == o.vertices && faces == o.faces && connectivity == o.connectivity;
  }
};

// The fingerprint of a base as given (before welding: the file's own vertices and faces).
BaseFingerprint fingerprint(const TriMesh& base);

struct SavedQuilt {
  // The quilt with empty positions: input_base.V and base.V have no rows until place_on_base.
  SurfaceQuilt quilt;
  QuiltEmbeddingOptions embedding;
  BaseFingerprint base;
  // The run's coverage check (cli: --min-coverage times what the swatch covers of itself).
  double min_coverage = 0, swatch_coverage = 0;
  std::string origin;  // what made it, for people: the swatch, method, scale
};

// Current version of the format (the file's 4 bytes after its magic).
inline constexpr std::uint32_t kSavedQuiltVersion = 1;

// The bytes of a saved quilt: a versioned little-endian binary ending in an FNV-1a 64 checksum
// of all bytes before it. Positions of the bases are left out (see SavedQuilt::quilt).
// Preconditions: the quilt's input_vertex is set (not a proxy base) and its arrays have
// consistent sizes. Throws InvalidInput for a proxy base (no input_vertex).
std::string serialize_saved_quilt(const SavedQuilt& saved);

// Parses what serialize_saved_quilt wrote. `name` names the file in messages. Throws
// InvalidInput "NAME: PROBLEM" (one line) for a wrong magic or version, a truncated or
// corrupted file (checksum), counts beyond the bytes present, and any index out of range,
// non-finite value or inconsistent size, so that a quilt read is safe to place.
SavedQuilt parse_saved_quilt(std::string_view bytes, const std::string& name);

// Writes atomically (no partial file on failure); read_saved_quilt reads through
// read_input_file (regular files of bounded size only).
void write_saved_quilt(const std::string& path, const SavedQuilt& saved);
SavedQuilt read_saved_quilt(const std::string& path);

// Gives the quilt the positions of `base`, the base it was made on with its vertices moved or
// not: its welded base from the base's vertices, its refined base by replaying the refinement's
// midpoints (bit for bit the synthesis's positions on the unmoved base). Throws InvalidInput
// when base's connectivity differs from `expected` ("the base has N vertices and M faces, the
// quilt was made on ..." or "the base's faces differ") or a position is not finite.
void place_on_base(SurfaceQuilt& quilt, const BaseFingerprint& expected, const TriMesh& base);

}  // namespace mq
