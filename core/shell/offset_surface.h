// The offset surface bounding the shell space of paper section 3.2 from outside: each base
// vertex moved along a smoothed normal by a per-vertex height, lowered where needed so that
// the shell between base and offset is a valid tetrahedral embedding.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

struct OffsetOptions {
  double height = 0.0;            // shell height w (> 0), e.g. a few % of the bbox diagonal
  int smoothing_iterations = 10;  // least Laplacian diffusion steps of the vertex normals (>= 0)
  // Diffusion reach in heights (>= 0): on a base whose mean edge e is short against the height,
  // the steps are raised to ceil((smoothing_radius * height / e)^2), since k steps of diffusion
  // reach about sqrt(k) edges. A finer tessellation of the same surface then gets the same
  // smoothing: with 10 steps alone the Stanford bunny split 1-to-4 twice (1.1M faces) had no
  // valid shell ("3 offending vertices at the minimum height"), as 70k and 278k faces had.
  double smoothing_radius = 1.25;
  double min_fraction = 0.1;  // no vertex's height drops below min_fraction * height
  int max_rounds = 64;        // bound on the shrink-and-check rounds (>= 1)

  // Throws InvalidInput for a value outside its range (above).
  void validate() const;
  // The same for the smoothing options alone (what offset_directions uses).
  void validate_smoothing() const;
};

// The offset vertices W = V + h_i d_i with their directions and heights.
//   V           #V by 3 offset positions
//   heights     #V heights h_i in [min_fraction * height, height] (0 for unreferenced vertices)
//   directions  #V by 3 unit directions d_i (zero for unreferenced vertices)
struct OffsetSurface {
  MatrixX3d V;
  int smoothing_steps = 0;  // diffusion steps taken (see OffsetOptions::smoothing_radius)
  Eigen::VectorXd heights;
  MatrixX3d directions;
};

// The unit directions offset_surface moves the vertices along (its first step, below), and in
// steps_out (if given) the diffusion steps taken: max(smoothing_iterations,
// ceil((smoothing_radius * height / mean edge)^2)). #V by 3.
// Throws InvalidInput for bad smoothing options (OffsetOptions::validate_smoothing);
// TopologyError as offset_surface.
MatrixX3d offset_directions(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options,
                            int* steps_out = nullptr);

// The directions the texture is displaced along where no shell map places it (normal
// displacement): offset_directions with the default smoothing for a shell of this height, or,
// where the base folds so that none exists, the area-weighted vertex normals. #V by 3.
// Throws InvalidInput for height <= 0 or bad input (as offset_directions).
MatrixX3d displacement_directions(const MatrixX3d& V, const MatrixX3i& F, double height);

// Offsets the base (V, F) outward.
// Directions: area-weighted vertex normals; where one lies closer than cos = 0.1 to the plane
// of an incident face (sharp vertices), the direction maximising the smallest cosine with the
// incident face normals replaces it. Then Laplacian diffusion steps, renormalised, each refused
// at a vertex where it would leave that cone (prisms below a face's plane are inverted at any
// height, so lowering could not repair them).
// Heights: all start at `height`; each round builds the shell prisms (shell_tet_indices) and
// finds faces with a non-positive or near-flat tet, and faces of the shell boundary (offset,
// base, side walls) that intersect each other (base-base pairs excepted: the base is given);
// every vertex of such a face has its height halved (not below the floor), then heights are
// graded (none more than twice its lowest neighbour's) so a lowered region tapers over a few
// rings. Heights only decrease; convex regions are not lowered, concave ones as far as needed.
//   V  #V by 3 base vertices (finite), F  #F by 3 faces, counter-clockwise seen from outside
// Deterministic; the result does not depend on the thread count.
// Throws InvalidInput for bad options (OffsetOptions::validate), non-finite coordinates, bad or
// repeated indices or no faces; TopologyError when a referenced vertex has no normal, when the base
// folds so that no direction lies above all of a vertex's faces (the message names the vertex), or
// when the shell stays invalid with every offending vertex at the height floor (or after
// max_rounds).
OffsetSurface offset_surface(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options);

// The vertices where the base folds for the shell: no normal, or no direction above all their
// faces (offset_surface's first test; no valid prism exists there at any height). Ascending.
//   V #V by 3 finite, F #F by 3. Throws InvalidInput for an index out of range.
std::vector<int> fold_vertices(const MatrixX3d& V, const MatrixX3i& F);

// Why no valid shell was found, and where: the message offset_surface throws; the offending
// vertices (ascending): those with no normal or no direction above their faces, or those still
// offending at the height floor (every offending one when max_rounds ran out); and, for the
// latter, the faces whose prisms offend (ascending): a flat or inverted tet, or an offset face
// or side wall meeting another boundary face of the shell.
struct OffsetFailure {
  std::string reason;
  bool fold = false;  // the base folds (a vertex has no normal or no direction above)
  std::vector<int> vertices;
  std::vector<int> faces;
};

// The first round's shell of a try_offset_surface call: its vertices (base then offset, at
// full height), boundary faces and their intersecting pairs. Passed to the next call on the
// same vertices (ShellMap's per-region fallback: most of the base again, a few regions left
// out), that call re-tests only the boundary faces that are new or moved and keeps the other
// pairs, so it finds exactly the pairs a full test would at a fraction of the cost (the ivy
// wall's 530k boundary faces: 0.45 s of each attempt's 0.6 s was the full test).
struct OffsetPairCache {
  MatrixX3d S;  // #2V by 3
  MatrixX3i B;  // boundary faces, as shell_boundary_faces
  std::vector<std::pair<int, int>> pairs;
};

// offset_surface without the TopologyError: returns false with `failure` filled instead (`out`
// is then unspecified), so that a caller can leave the offending region out of the shell and
// try again (ShellMap's per-region fallback). Same arguments and other throws. cache
// (optional): read when it holds an earlier call's first round on as many vertices, then
// replaced by this call's; the result does not depend on it.
bool try_offset_surface(const MatrixX3d& V, const MatrixX3i& F, const OffsetOptions& options,
                        OffsetSurface& out, OffsetFailure& failure,
                        OffsetPairCache* cache = nullptr);

}  // namespace mq
