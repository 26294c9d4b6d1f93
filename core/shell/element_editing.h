// Editing a saved quilt element by element (issue 25; paper section 1: elements stay whole so
// the result can be edited afterwards): choose elements by id, kind or region, then remove them
// or give them a material (a kind: every format gives each kind its own material). `meshquilt
// embed` writes the edited quilt on any pose of its base.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/shell/saved_quilt.h"

namespace mq {

// Which elements an edit applies to: those meeting every criterion given (none: all). Elements
// are the output's connected components, numbered by first face as every written file numbers
// them (element_id); regions test the element's centre (the mean of its vertices) at rest.
struct ElementSelection {
  std::vector<int> ids;  // element ids; empty: any
  std::string kind;      // the element's kind; empty: any
  bool sphere = false;
  Vector3d centre = Vector3d::Zero();
  double radius = 0;
  bool box = false;
  Vector3d lo = Vector3d::Zero(), hi = Vector3d::Zero();
  // Throws InvalidInput for a negative id, a radius not positive and finite, or a box with lo
  // above hi or not finite.
  void validate() const;
};

// #elements flags: the elements `selection` chooses. Throws InvalidInput for an id beyond the
// quilt's elements or a kind it does not have (naming the kinds it has).
std::vector<char> select_elements(const SavedQuilt& quilt, const ElementSelection& selection);

// The mesh without the chosen elements (#elements flags, face_component from
// connected_components): the other faces in order, their vertices in order, kinds and face kinds
// kept. vertex_map: optional output, per vertex of the result its vertex in `mesh`.
TriMesh without_elements(const TriMesh& mesh, const std::vector<int>& face_component,
                         const std::vector<char>& chosen, std::vector<int>* vertex_map = nullptr);

// Removes the chosen elements (their faces, vertices and local coordinates); the others keep
// their order, so element ids after the removal count only the kept ones. Kinds no face uses
// any more are dropped.
void remove_elements(SavedQuilt& quilt, const std::vector<char>& chosen);

// Gives the chosen elements the kind `name` (a material of its own in every file; a name of the
// form color_RRGGBB, hexadecimal, is that colour: element_kinds' kind_material).
void set_element_kind(SavedQuilt& quilt, const std::vector<char>& chosen, const std::string& name);

// Gives each chosen element one of `count` kinds NAME_1 .. NAME_count at random (seeded), NAME
// its kind: a palette of looks over the same elements, the same for the same seed.
// Throws InvalidInput for count < 1 or above 256.
void assign_palette(SavedQuilt& quilt, const std::vector<char>& chosen, int count,
                    std::uint64_t seed);

}  // namespace mq
