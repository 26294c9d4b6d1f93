// Kinds of geometry element (section 2.1: a swatch's elements may differ, e.g. an ivy section's
// vine and leaves, a weave's threads along x and along y). A kind is a name; a mesh stores the
// names once (TriMesh::kinds) and one index per face (TriMesh::face_kind). Every face of an
// element (connected component) has the element's kind.
#pragma once

#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// The name given to the elements of a mesh whose file names no kind.
inline const char* const kDefaultKind = "element";

// Whether mesh carries kinds: kinds not empty and face_kind #F.
bool has_kinds(const TriMesh& mesh);

// Gives every face of mesh the one kind `name` (replacing any kinds it had).
void set_single_kind(TriMesh& mesh, const std::string& name);

// Throws InvalidInput unless face_kind is empty, or #F indices into kinds.
void check_kinds(const TriMesh& mesh);

// Makes mesh carry kinds: a mesh without any gets the single kind kDefaultKind.
// Throws InvalidInput when face_kind is neither empty nor #F, or holds an index out of range.
void ensure_kinds(TriMesh& mesh);

// The kind index of each connected component: the kind most of its faces have (the lowest
// index on a tie), so an element read from a file whose groups cut through it has one kind.
//   face_component  #F component of each face, in [0, num_components)
// Returns #components indices into mesh.kinds (all 0 when mesh has no kinds).
std::vector<int> component_kinds(const TriMesh& mesh, const std::vector<int>& face_component,
                                 int num_components);

// Removes kinds no face uses, keeping the order of the others (kinds stay empty if they were).
void remove_unused_kinds(TriMesh& mesh);

// The index of `name` in kinds, appending it when absent.
int kind_index(std::vector<std::string>& kinds, const std::string& name);

// A kind name usable as an OBJ group, material and glTF material name: printable ASCII without
// spaces ('_' replaces anything else); an empty name becomes kDefaultKind.
std::string sanitized_kind(const std::string& name);

// The kinds' names as files write them: each sanitized_kind, and those equal after that (two
// unnamed kinds, "a b" beside "a_b", "kind_1" beside an unnamed kind) told apart by a suffix
// "_2", "_3", ... in order, so that every format names #kinds distinct materials (issue 28).
std::vector<std::string> unique_kind_names(const std::vector<std::string>& kinds);

// The elements of a mesh as files label them: element e is connected component e (in order of
// first face, as split_elements numbers them), of kind element_kind[e] in kinds.
struct ElementLabels {
  int count = 0;
  std::vector<int> face_element;    // #F
  std::vector<int> vertex_element;  // #V: the element of each vertex (0 for unused ones)
  std::vector<int> element_kind;    // #elements, indices into kinds
  std::vector<std::string> kinds;   // the mesh's kinds, or {kDefaultKind} when it has none
};
ElementLabels element_labels(const TriMesh& mesh);

// How a kind looks in the files that carry materials (OBJ .mtl, glTF): a base colour (linear
// RGB in [0, 1]) and metal-roughness parameters. The sample kinds have fitting looks (steel
// rings, two yarn shades, bark vine, green leaves, red apples); a name color_RRGGBB (sRGB in
// hexadecimal) that colour; any other name a colour from a hash of it, so the same name looks
// the same in every file.
struct KindMaterial {
  double r = 0.7, g = 0.7, b = 0.7;
  double metallic = 0;
  double roughness = 0.6;
};
KindMaterial kind_material(const std::string& kind);

}  // namespace mq
