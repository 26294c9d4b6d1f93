// Local repair of folds in a base surface, for building the shell space of paper section 3.2
// only: a face that points against its neighbours (a fold, as near vertices 5099/5165 of
// cup_mug_11k) has no offset direction above it and its neighbours, so every shell prism there
// is inverted at any height. The folded vertices are relaxed towards their 1-ring centroid
// until the surface no longer folds; the shell is then built over the repaired base. The
// texture is placed through that shell but shown over the base as given, so the relaxation is
// bounded: a relaxed vertex stays within a small distance of the base as given (issue 23: an
// unbounded relaxation shrank the open quadruped's legs by 0.55 units under a shell 0.05 high,
// and the texture sank into them). Folds the bounded relaxation cannot undo are reported, for
// the caller to leave out of the shell.
#pragma once

#include <limits>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

struct FoldRepairOptions {
  int smoothing_iterations = 10;  // centroid relaxation steps per round (>= 1)
  int max_rounds = 8;             // each round grows the relaxed region by one ring (>= 1)
  // How far a relaxed vertex may lie from the base as given, on its outer side and under it
  // (signed distance, pseudo-normal side; >= 0, infinity: unbounded). A relaxation step that
  // would take a vertex farther is pulled back towards its closest point on the base, so the
  // vertex may slide along the surface but not leave it.
  double max_above = std::numeric_limits<double>::infinity();
  double max_below = std::numeric_limits<double>::infinity();
  // How far a vertex may move in all (>= 0, infinity: unbounded): sliding along the base moves
  // the texture placed over it, so the repair stays local.
  double max_shift = std::numeric_limits<double>::infinity();
  // Judge folds by offset_surface's own test (fold_vertices: a vertex with no direction above
  // all its faces) instead of folded_faces: only what keeps the shell from being built is
  // relaxed. folded_faces also flags sharp rims that the shell can cover (Blender's Suzanne: 74
  // faces, against none for the shell), and relaxing them all moved half of its vertices.
  bool offset_criterion = false;
};

//   V                #V by 3 repaired positions (equal to the input except at moved vertices)
//   folded_faces     faces found folded in the input, ascending
//   unrepaired_faces faces still folded after max_rounds (ascending; empty when repaired)
//   moved_vertices   vertices whose position changed, ascending
//   max_displacement largest distance a vertex moved
//   max_above, max_below  largest distance of a moved vertex from the base as given, above it
//                    and under it (0 when none is; computed only when a bound is set)
struct FoldRepair {
  MatrixX3d V;
  std::vector<int> folded_faces;
  std::vector<int> unrepaired_faces;
  std::vector<int> moved_vertices;
  double max_displacement = 0.0;
  double max_above = 0.0, max_below = 0.0;
};

// Folded faces: a face whose unit normal has a negative dot product with the area-weighted sum
// of its edge neighbours' normals, or one incident to a vertex whose area-weighted normal has a
// negative dot product with one of its faces (no direction lies above all of them).
//   V #V by 3, F #F by 3 (consistently oriented). Returns ascending face indices.
// Throws InvalidInput for an index out of range.
std::vector<int> folded_faces(const MatrixX3d& V, const MatrixX3i& F);

// Relaxes the vertices of folded faces (Jacobi steps towards the 1-ring centroid, in fixed
// order, each kept within the bounds: deterministic), growing the relaxed set by one ring per
// round until folded_faces is empty or max_rounds have run; faces still folded are returned in
// unrepaired_faces. With offset_criterion, the fold vertices instead, until there are none
// (unrepaired_faces: the faces of those left). A base without folds is returned unchanged.
//   V #V by 3 finite, F #F by 3 consistently oriented
// Throws InvalidInput for bad options, an index out of range or non-finite coordinates.
FoldRepair repair_folds(const MatrixX3d& V, const MatrixX3i& F,
                        const FoldRepairOptions& options = {});

}  // namespace mq
