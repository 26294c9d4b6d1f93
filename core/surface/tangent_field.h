// Guidance vector fields on a base mesh (paper section 3.1: an optional field orients the
// synthesis on curved surfaces): unit tangent vectors per face, from a world direction, from
// per-vertex vectors, from key vectors interpolated over the surface (as in Lai et al.'s geometry
// texture synthesis, section 4.3), or a smooth default.
//
// Common contract of the #F by 3 fields returned here: every row is a unit vector orthogonal
// to its face normal (a face of zero area gets a unit vector too; its normal is undefined).
// Where the construction leaves a face undefined (the source is parallel to the normal, or zero),
// the field is filled from already-defined faces sharing a vertex, wave by wave (each face takes
// the normalised sum of its defined neighbours projected into its plane); faces that no wave
// reaches (a component without any defined face) take the projection of the bounding box's
// longest axis (or the next longest where that is parallel to the normal).
#pragma once

#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

// (a) A constant world direction projected onto each face plane.
//   V #V by 3, F #F by 3, direction finite and non-zero
// Returns #F by 3. Throws InvalidInput for a zero or non-finite direction, one normal to every
// face (no part along the surface), or a bad index.
MatrixX3d tangent_field_from_direction(const MatrixX3d& V, const MatrixX3i& F,
                                       const Vector3d& direction);

// (b) Per-vertex vectors from a text file: one "x y z" line per vertex, in vertex order; '#'
// starts a comment, blank lines are skipped. Returns num_vertices by 3 (not normalised).
// Throws InvalidInput naming file:line for a line without exactly three finite numbers or for a
// vector beyond num_vertices, naming the file for an unreadable file or too few vectors.
MatrixX3d read_vertex_vector_field(const std::string& path, int num_vertices);

// Face field from per-vertex vectors: the mean of a face's three vectors projected onto its
// plane and normalised (undefined where that vanishes, then filled as above).
//   vertex_vectors #V by 3, finite (zero rows allowed)
// Returns #F by 3. Throws InvalidInput for a size mismatch, a non-finite vector or a bad index.
MatrixX3d tangent_field_from_vertex_vectors(const MatrixX3d& V, const MatrixX3i& F,
                                            const MatrixX3d& vertex_vectors);

// (c) A key vector: a direction given at one vertex.
struct KeyVector {
  int vertex = -1;
  Vector3d direction = Vector3d::Zero();
};

// Key vectors from a text file: lines "vertex_index x y z"; '#' comments, blank lines skipped.
// Throws InvalidInput naming file:line for a malformed line, an index outside
// [0, num_vertices), a zero or non-finite direction or a repeated vertex; naming the file when
// it cannot be read. An empty list is returned for a file without key lines.
std::vector<KeyVector> read_key_vectors(const std::string& path, int num_vertices);

// Interpolation of the key vectors over the surface by diffusion: each key is projected into its
// vertex's tangent plane (area-weighted vertex normal) and normalised; the three coordinates are
// then interpolated independently as the minimiser of the discrete bilaplacian energy
// x^T L M^-1 L x with the keys as Dirichlet values (L: cotangent Laplacian with edge weights
// clamped below at 1e-3, M: lumped barycentric mass; one factorisation). The plain harmonic
// (Laplacian) interpolant was tried first: with point constraints it is spiky, the keys barely
// influence their own neighbourhood; the biharmonic one is smooth through the keys.
// Returns #V by 3 unit vectors in the vertex tangent planes; at a key vertex exactly its
// projected key. Vertices of components without keys, or where the interpolant vanishes, get
// the vertex_tangent_field of the face field below; unreferenced vertices get zero rows.
// Throws InvalidInput for no keys, a key index out of range or unused by F, a zero or
// non-finite key, a key parallel to its vertex normal, a repeated key vertex or a bad index;
// SolverFailure when the factorisation fails.
MatrixX3d vertex_field_from_key_vectors(const MatrixX3d& V, const MatrixX3i& F,
                                        const std::vector<KeyVector>& keys);

// Face field of the same interpolation: the mean of the three interpolated (unnormalised)
// vertex vectors projected onto the face plane and normalised; undefined faces (components
// without keys) filled as above. Returns #F by 3. Same throws.
MatrixX3d tangent_field_from_key_vectors(const MatrixX3d& V, const MatrixX3i& F,
                                         const std::vector<KeyVector>& keys);

// The default field without user input, chosen so that neighbouring patches agree: the
// projection of the bounding box's longest axis (lowest axis index on ties) onto each face,
// filled where parallel to the normal, then `iterations` Jacobi smoothing steps over
// edge-adjacent faces (each face takes the normalised sum of itself and its neighbours, all
// projected into its plane), which spreads out the singularities where the axis meets the
// normal. Deterministic; defined on every face of any genus or number of components.
// Returns #F by 3. Throws InvalidInput for a bad index or iterations < 0.
MatrixX3d smooth_tangent_field(const MatrixX3d& V, const MatrixX3i& F, int iterations = 20);

// Per-vertex field from a face field: the area-weighted sum of incident face vectors projected
// onto the vertex tangent plane and normalised (the largest incident face's vector where that
// vanishes); zero rows for unreferenced vertices.
//   face_field #F by 3. Returns #V by 3. Throws InvalidInput for a size mismatch or bad index.
MatrixX3d vertex_tangent_field(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& face_field);

}  // namespace mq
