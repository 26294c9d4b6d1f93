// Reading and writing triangle meshes in OBJ, PLY and OFF.
//
// Files are read whole into memory and parsed by hand (std::from_chars) and written through a
// large buffer (std::to_chars), so meshes with millions of faces load and save in seconds.
#pragma once

#include <functional>
#include <string>

#include "core/mesh/mesh.h"

namespace mq {

enum class MeshFormat { Obj, Ply, Off, Glb };

// Format from the file extension (.obj .ply .off .glb, case-insensitive); .glb is written only.
// Throws InvalidInput naming the file for any other extension.
MeshFormat mesh_format_from_path(const std::string& path);

// Reads a triangle mesh from an OBJ, PLY or OFF file (format chosen by extension).
//
// Polygons with more than three corners are fan-triangulated (0,i,i+1). OBJ faces may use the
// "v", "v/vt", "v//vn" and "v/vt/vn" forms and negative (relative) indices; other OBJ
// statements (vt, l, ...) are ignored. Element kinds (element_kinds.h) come from OBJ usemtl
// names, else g/o names (sanitized_kind), and from a PLY integer vertex property `kind` named by
// "comment kind K NAME" header lines (a face takes its first vertex's); otherwise kinds is empty.
// OFF accepts the OFF/COFF/NOFF/CNOFF/STOFF headers and '#' comments. PLY accepts ascii,
// binary_little_endian and binary_big_endian, any order of vertex properties (x y z as any scalar
// type), face lists with any integer count and index types, and skips unknown properties and
// elements.
//
// Returns V (#V by 3), F (#F by 3, 0-based) and N (#V by 3) when the file carries complete
// per-vertex normals (PLY nx ny nz, NOFF normals, or OBJ vn referenced consistently by every
// corner of every vertex); otherwise N is empty. Unreferenced vertices are kept.
//
// Throws InvalidInput "FILE:LINE: problem" (for binary PLY "FILE: <element> N: problem") for a
// missing or unreadable file, an empty file or one with no faces, an unknown format, truncated
// data, a bad or out-of-range index, a face with fewer than 3 vertices, a NaN/Inf coordinate, a
// malformed number, or unsupported PLY content.
TriMesh read_mesh(const std::string& path);

// Parses the bytes of a mesh file in the given format, as read_mesh does once it has read
// them; `path` only names the data in messages. Throws like read_mesh. (The fuzz targets in
// fuzz/ call it directly.)
TriMesh read_mesh_data(const std::string& data, MeshFormat format, const std::string& path);

// How an OBJ groups its faces: one object per element (named KIND_ID, the element id zero-padded),
// one per kind, or none.
enum class ElementGroups { Element, Kind, None };

struct WriteOptions {
  // PLY only: binary little-endian (true) or ASCII (false).
  bool binary = true;
  // Write normals (OBJ vn, PLY nx ny nz, NOFF; glTF always has them). Uses mesh.N when it is
  // #V by 3; otherwise computes them: per corner in OBJ and glTF (corner_normals.h, split at
  // edges sharper than crease_degrees), area-weighted per vertex in PLY and OFF.
  bool write_normals = false;
  double crease_degrees = 60;
  // Write element identity (element e = connected component e in order of first face) and
  // kinds (mesh.kinds; kDefaultKind when empty): OBJ groups as `groups` says, `usemtl KIND`
  // and a NAME.mtl beside the file (written first) with one material per kind; PLY vertex
  // properties `int element_id` and `int kind` with "comment kind K NAME" lines (and
  // "comment kind_material K R G B METALLIC ROUGHNESS", the kind's kind_material). glTF always
  // has them (gltf_writer.h); OFF has no place for them.
  bool write_elements = false;
  ElementGroups groups = ElementGroups::Element;
  // Significant digits for coordinates in text formats; 17 round-trips doubles exactly.
  // A value <= 0 writes the shortest text that round-trips exactly.
  int precision = 9;
  // A file committed together with the mesh (core/mesh/atomic_file's commit_with), none when
  // the path is empty: its bytes are made by companion_bytes once the mesh is written out, and
  // it is renamed after it (issue 28: the --stats file).
  std::string companion_path;
  std::function<std::string()> companion_bytes;
};

// Writes mesh to path in the format given by its extension (.glb: write_glb). Output bytes depend
// only on the mesh and options. PLY coordinates are stored as double.
//
// The data go to a temporary file in the same directory which is then renamed over path, so a
// failed or interrupted write never leaves a partial file at path (an existing file is kept).
//
// Preconditions: V finite; F entries in [0, #V); N, when used, finite and #V by 3; face_kind
// empty or #F indices into kinds when kinds is not empty.
// Throws InvalidInput for an unknown extension or a violated precondition; Error naming the file
// for an I/O failure (unwritable directory, disk full).
void write_mesh(const std::string& path, const TriMesh& mesh, const WriteOptions& options = {});

}  // namespace mq
