// Local surface patches on a base mesh (paper section 3.1): a patch grows from a seed triangle by
// breadth-first traversal, stays a topological disk, and is flattened by a least-squares
// conformal map; it shrinks while the map's area distortion exceeds a bound.
#pragma once

#include <cstdint>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

struct LocalPatchOptions {
  double max_area = 0;  // stop growing once the patch area reaches this (0: unlimited)
  // stop at faces whose centroid lies farther than this from the seed's, measured along the
  // surface as in LocalPatchBuilder::grow (0: unlimited)
  double max_radius = 0;
  // Shrink while the 95th percentile of the face area distortions exceeds this (>= 1).
  double max_distortion = 4;
};

struct LocalPatch {
  std::vector<int> faces;       // base face ids in growth order, seed first
  TriMesh mesh;                 // the patch's own vertices and faces (F rows match faces)
  std::vector<int> vertex_map;  // patch vertex -> base vertex
  MatrixX2d uv;                 // LSCM of the patch, #patch V by 2, area-matched to 3D
  double max_distortion = 1;    // worst face area distortion of uv
  double distortion = 1;        // 95th percentile of the face area distortions (what is bounded)
  int shrink_steps = 0;         // how many times the patch was halved
  double area = 0;              // 3D area of the patch
};

// Grows and flattens local patches on one base mesh. Keeps per-face and per-vertex stamp arrays
// so that each grow() costs time proportional to the patch, not to the base mesh.
// Not thread-safe (grow() uses the workspace): use one builder per thread.
class LocalPatchBuilder {
 public:
  // base is borrowed and must outlive the builder; its topology is computed here (O(#F log #F)).
  // Throws InvalidInput for an index out of range or a non-finite position.
  explicit LocalPatchBuilder(const TriMesh& base);
  // Same with precomputed topology (copied): topo = edge_topology(base.F, #V),
  // TT = face_adjacency(topo). Throws InvalidInput when their sizes do not match base.
  LocalPatchBuilder(const TriMesh& base, const EdgeTopology& topo, const MatrixX3i& TT);

  // Grows a patch from seed_face across manifold edges (TT), nearest faces first (distance from
  // the seed's centroid unfolded along the path that reached the face, at least the straight
  // distance; ties by face id), until its area reaches
  // options.max_area or the next face lies beyond options.max_radius. A face is added only when
  // the patch stays a topological disk: it shares one edge with the patch and brings a new
  // vertex, or it shares two edges and closes a notch; faces with zero area or a repeated vertex
  // are never added. A refused face is retried whenever a neighbour of it joins the patch. The
  // patch is then flattened with lscm; while the 95th percentile face area distortion exceeds
  // max_distortion or a UV triangle is flipped, the patch is cut to the longest prefix of its
  // growth order with at most half its area (every prefix is a disk) and flattened again.
  // Guarantees: one boundary loop, Euler characteristic 1, the seed is faces[0], area <
  // max_area + area of one face (when max_area > 0). The result may still exceed max_distortion
  // only when it is down to the seed alone.
  // Throws InvalidInput for a seed out of range or degenerate, or bad options (max_area < 0 or
  // not finite, max_radius < 0 or not finite, max_distortion < 1 or NaN); SolverFailure from lscm.
  LocalPatch grow(int seed_face, const LocalPatchOptions& options = {});

  const TriMesh& base() const { return *base_; }

 private:
  void init();
  bool can_add(int f) const;
  Vector3d unfold_across(int f, int k, int g, const Vector3d& p) const;
  void flatten(LocalPatch& patch, size_t num_faces);
  uint32_t next_tick();

  const TriMesh* base_;
  EdgeTopology topo_;
  MatrixX3i TT_;
  Eigen::VectorXd area_;
  MatrixX3d centroid_;
  // Per base face, valid when face_seen_ == patch tick: distance from the seed and the seed's
  // centroid unfolded into the face's plane.
  std::vector<double> distance_;
  MatrixX3d seed_image_;
  std::vector<char> usable_;             // per base face: non-degenerate
  std::vector<uint32_t> face_in_patch_;  // == patch tick when in the current patch
  std::vector<uint32_t> face_seen_;      // == patch tick when distance_ is set for this patch
  std::vector<uint32_t> vertex_in_patch_;
  std::vector<uint32_t> vertex_local_tick_;
  std::vector<int> vertex_local_;
  uint32_t tick_ = 0;
  uint32_t patch_tick_ = 0;
};

// One-off form: LocalPatchBuilder(base, topo, TT).grow(seed_face, options); O(#F) setup.
LocalPatch grow_local_patch(const TriMesh& base, const EdgeTopology& topo, const MatrixX3i& TT,
                            int seed_face, const LocalPatchOptions& options);

}  // namespace mq
