// A saved quilt placed on its base moved (issue 25; paper section 3.2's promise that the
// output can follow edits of the base without a new synthesis). Each output vertex keeps its
// prism coordinates (core/shell/prism_coordinates) and moves by what they move by from the base
// at rest to the base given. Compact elements (rings, leaves) then take the rigid motion that
// fits that best (Kabsch), so they turn and travel with the surface but are not stretched with
// it; long ones (threads, stems) follow the surface vertex by vertex.
#pragma once

#include <vector>

#include "core/shell/saved_quilt.h"
#include "core/surface/surface_quilting.h"

namespace mq {

// The saved quilt of a synthesis: `output` is embed_quilt's result for `quilt`, located in the
// prisms of quilt.input_base, or of quilt.welded_base when that is a proxy (locate_in_prisms;
// `inexact` counts the vertices it could not place exactly). Throws InvalidInput when neither
// has its input_vertex.
SavedQuilt make_saved_quilt(const SurfaceQuilt& quilt, const TriMesh& output,
                            SavedQuiltHeader header, int* inexact = nullptr);

struct FollowBaseOptions {
  // An element whose vertices all lie within this many shell heights of its centroid is
  // compact: it moves rigidly. 0: every element follows the surface.
  double rigid_radius = 3.0;
  // Rigid elements that come to intersect another element (the surface shrinks under them:
  // the inside of a bend) follow the surface instead; those still intersecting are shrunk
  // (95% to 60% of their size) or else removed, as the synthesis's post-processing does.
  // false: keep every element as moved.
  bool resolve_intersections = true;
  // Never remove an element (a result bound to its base in Blender keeps its faces and element
  // ids from frame to frame): those that would go stay at 60% of their size, pressed into a
  // neighbour, or rigid where following the surface folds them.
  bool keep_elements = false;
  // Elements removed whatever happens (#elements flags, or empty): a sequence removes the union
  // of what each frame removes, so every frame has the same faces.
  std::vector<char> remove;
  // Throws InvalidInput for a negative or non-finite radius.
  void validate() const;
};

struct FollowBaseStats {
  int elements = 0;
  int rigid = 0;              // compact elements moved rigidly
  int following = 0;          // long elements that followed the surface
  int unmoved = 0;            // where the base did not move: kept bit for bit
  int unbent = 0;             // rigid elements that intersected another, made to follow the surface
  int shrunk = 0;             // then still intersecting, kept at 60-95% of their size
  int pressed_pairs = 0;      // keep_elements: pairs of elements left intersecting
  std::vector<char> removed;  // #elements: removed (intersecting after that, or asked to)
  int num_removed = 0;
  // Over the moved elements: the largest displacement, in shell heights, of a vertex from where
  // it would be following the surface (what the rigid motion changes).
  double largest_rigid_offset = 0;
};

// The output on the base whose welded positions are `V` (welded_positions): #V(saved.base) by 3.
// An element the base does not move for is kept bit for bit, so the unmoved base gives the
// saved output exactly. TBB over elements, each writing its own vertices: independent of the
// thread count. Throws InvalidInput when V has not the welded base's vertex count or is not
// finite, and for invalid options.
TriMesh follow_base(const SavedQuilt& saved, const MatrixX3d& V, const FollowBaseOptions& options,
                    FollowBaseStats* stats = nullptr);

}  // namespace mq
