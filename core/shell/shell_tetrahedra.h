// The shell space of paper section 3.2: the thin volume between a base surface (V, F) and an
// offset (W, F) of it, as one prism per face split into three tetrahedra.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"
#include "core/shell/tet_mesh.h"

namespace mq {

// The combinatorial split, no geometry: vertex i of the base is shell vertex i, its offset is
// shell vertex n + i. The prism over face (a, b, c) is cut by the "sort vertex ids" rule: with
// v0 < v1 < v2 its sorted corners, the tets are (v0 v1 v2 v0'), (v1 v2 v0' v1'),
// (v2 v0' v1' v2'), so the side quad over an edge (i, j), i < j, is always cut by the diagonal
// j-i'. The rule depends on the edge only, hence neighbouring prisms agree and the tet mesh is
// conforming. Tets are ordered so that they have positive volume when the offset lies on the
// side of each face's normal (counter-clockwise F). Face f gives tets 3f, 3f + 1, 3f + 2.
//   F  #F by 3 faces, indices in [0, n), no repeated index within a face
// Returns 3#F by 4. Throws InvalidInput for an out-of-range or repeated index.
TetIndices shell_tet_indices(const MatrixX3i& F, int num_base_vertices);

// The shell tet mesh: vertices = base_V then offset_V (2n), tets = shell_tet_indices(F, n).
//   base_V    n by 3 base vertices (finite)
//   offset_V  n by 3 offset vertices (finite), offset_V.row(i) the offset of base_V.row(i)
//   F         #F by 3 faces of the base, counter-clockwise seen from the offset side
// Throws InvalidInput for mismatched sizes, non-finite coordinates or bad indices;
// TopologyError when a tet is inverted or degenerate (volume <= 1e-12 * longest edge^3),
// which means the offset is invalid there (the message names the face).
TetMesh shell_tetrahedra(const MatrixX3d& base_V, const MatrixX3d& offset_V, const MatrixX3i& F);

// The triangles bounding the shell, oriented outward from it, indices into the shell vertices:
// the base faces reversed, the offset faces, and for an open base two triangles per boundary
// edge on the side wall, cut by the same diagonal as the tets (so each is a face of one tet).
// Returns (2#F + 2#boundary edges) by 3, in that order. Throws like shell_tet_indices.
MatrixX3i shell_boundary_faces(const MatrixX3i& F, int num_base_vertices);

// Faces of the triangle soup (V, F) that intersect another face other than along shared
// vertices or edges, found by TetGen's exact-predicate PLC check (tetrahedralize with "pdQ":
// -d makes it report intersecting facets instead of meshing). TetGen serves as an independent
// check of the double-precision test in core/mesh/mesh_intersections.h. Coincident faces count as
// intersecting. Deterministic (TetGen is sequential).
//   V  #V by 3 finite positions, F  #F by 3 indices, every face of non-zero area
// Returns ascending face indices. Throws InvalidInput for bad indices, non-finite or zero-area
// faces (TetGen's own error path is unreliable in 1.5.0, so such input is refused before), and
// when an intersecting face lies on coincident vertices (TetGen merges them);
// SolverFailure when TetGen reports an error (it throws an int code in library mode).
std::vector<int> tetgen_intersecting_faces(const MatrixX3d& V, const MatrixX3i& F);

// Validity of a shell (base_V, offset_V, F) as a tetrahedral embedding.
struct ShellValidation {
  int num_tets = 0;
  int num_nonpositive_tets = 0;  // volume <= 1e-12 * longest edge^3
  double min_volume = 0.0;
  // Rows of shell_boundary_faces(F, n) that intersect another boundary face (TetGen).
  std::vector<int> intersecting_boundary_faces;
  bool valid() const { return num_nonpositive_tets == 0 && intersecting_boundary_faces.empty(); }
};

// All tets positive and the shell boundary free of self-intersections: together these make
// the tets a non-overlapping filling of the region the boundary encloses.
// Throws InvalidInput like shell_tetrahedra and tetgen_intersecting_faces (the latter also
// when a boundary face has zero area, e.g. a zero offset height).
ShellValidation validate_shell(const MatrixX3d& base_V, const MatrixX3d& offset_V,
                               const MatrixX3i& F);

}  // namespace mq
