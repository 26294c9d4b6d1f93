// A saved quilt (issue 25; paper section 3.2: the output is kept in local coordinates over the
// base, so the base can be edited or animated without a new synthesis): the output of a run, each
// vertex in prism coordinates over the welded base, with the welded base at rest and a
// fingerprint of the base's connectivity. `meshquilt surface --save-quilt` writes one,
// `meshquilt embed` (core/shell/follow_base) places it on the base moved; on the unchanged
// base that gives the synthesis's output byte for byte.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/shell/prism_coordinates.h"

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

// What a saved quilt keeps beside the geometry.
struct SavedQuiltHeader {
  BaseFingerprint base;
  double shell_height = 0;  // H, in the base's units
  std::string origin;       // what made it, for people: the swatch, method, scale
};

// The output of a synthesis in prism coordinates over its welded base.
struct SavedQuilt {
  SavedQuiltHeader header;
  // #V(base): the vertex of the base as given each welded base vertex is.
  std::vector<int> input_vertex;
  TriMesh base;    // the welded base at rest (V, F)
  TriMesh output;  // the output at rest (V, F, kinds, face_kind); its elements its components
  LocalCoordinates coords;  // #V(output), in the prisms over `base` (prism_coordinates)
};

// Current version of the format (the file's 4 bytes after its magic).
inline constexpr std::uint32_t kSavedQuiltVersion = 1;

// The bytes of a saved quilt: a versioned little-endian binary ending in an FNV-1a 64 checksum
// of all bytes before it (layout: docs/saved-quilt.md).
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

// The welded base's positions for `base`, the base the quilt was made on with its vertices
// moved or not. Throws InvalidInput when base's connectivity differs from the quilt's ("the base
// has N vertices and M faces, the quilt was made on ..." or "the base's faces differ") or a
// position is not finite.
MatrixX3d welded_positions(const SavedQuilt& saved, const TriMesh& base);

}  // namespace mq
