// glTF 2.0 binary (.glb) output for the artists' tools (Blender, game engines), written with
// tinygltf (Debian libtinygltf-dev, the maintained C++ glTF reader and writer).
//
// The file holds one node with one mesh and one primitive per kind of element (TriMesh::kinds,
// element_kinds.h), each with its own material (kind_material), all sharing one vertex set:
//   POSITION     float VEC3, with min and max as the format requires
//   NORMAL       float VEC3, per corner split at edges sharper than the crease angle
//                (corner_normals.h), so a vertex of the mesh becomes one glTF vertex per normal
//   _ELEMENT_ID  float SCALAR, the element id (connected component, in order of first face);
//                a float because glTF allows only float or normalized vertex attributes in
//                general; ids are exact below 2^24
// and indices as unsigned int. Bytes depend only on the mesh and options.
#pragma once

#include <string>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"

namespace mq {

// Writes mesh as a .glb to path, atomically (atomic_file.h).
// Preconditions as write_mesh. Throws InvalidInput for a mesh with more than 2^24 elements or
// 2^32-1 glTF vertices, Error naming the file for an I/O failure.
void write_glb(const std::string& path, const TriMesh& mesh, const WriteOptions& options = {});

}  // namespace mq
