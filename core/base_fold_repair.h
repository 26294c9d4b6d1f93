// Local repair of folds in a base surface, for building the shell space of paper section 3.2
// only: a face that points against its neighbours (a fold, as near vertices 5099/5165 of
// cup_mug_11k) has no offset direction above it and its neighbours, so every shell prism there
// is inverted at any height. The folded vertices are relaxed towards their 1-ring centroid
// until the surface no longer folds; the shell is then built over the repaired base.
#pragma once

#include <vector>

#include "core/mesh.h"

namespace mq {

struct FoldRepairOptions {
  int smoothing_iterations = 10;  // centroid relaxation steps per round (>= 1)
  int max_rounds = 8;             // each round grows the relaxed region by one ring (>= 1)
};

//   V              #V by 3 repaired positions (equal to the input except at moved vertices)
//   folded_faces   faces found folded in the input, ascending
//   moved_vertices vertices whose position changed, ascending
//   max_displacement largest distance a vertex moved
struct FoldRepair {
  MatrixX3d V;
  std::vector<int> folded_faces;
  std::vector<int> moved_vertices;
  double max_displacement = 0.0;
};

// Folded faces: a face whose unit normal has a negative dot product with the area-weighted sum
// of its edge neighbours' normals, or one incident to a vertex whose area-weighted normal has a
// negative dot product with one of its faces (no direction lies above all of them).
//   V #V by 3, F #F by 3 (consistently oriented). Returns ascending face indices.
// Throws InvalidInput for an index out of range.
std::vector<int> folded_faces(const MatrixX3d& V, const MatrixX3i& F);

// Relaxes the vertices of folded faces (Jacobi steps towards the 1-ring centroid, in fixed
// order: deterministic), growing the relaxed set by one ring per round until folded_faces is
// empty. A base without folds is returned unchanged.
// Throws InvalidInput for bad options, an index out of range or non-finite coordinates;
// TopologyError when folds remain after max_rounds (the message names a folded face).
FoldRepair repair_folds(const MatrixX3d& V, const MatrixX3i& F,
                        const FoldRepairOptions& options = {});

}  // namespace mq
