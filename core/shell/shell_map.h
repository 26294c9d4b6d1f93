// The shell map of paper section 3.2: a piecewise-linear bijection between the shell space
// (tets between the base surface and its offset) and the texture space (the base's texture
// atlas extruded by the shell height), and the optimisation of its stretch (Eqs. 8-9).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/shell/base_fold_repair.h"
#include "core/shell/offset_surface.h"
#include "core/shell/tet_mesh.h"
#include "core/shell/tet_stretch.h"
#include "core/shell/texture_atlas.h"

namespace mq {

struct ShellMapOptions {
  double height = 0.0;  // shell height H (> 0); overrides offset.height
  OffsetOptions offset;
  TextureAtlasOptions atlas;
  // When offset_surface rejects the base, relax its folded vertices (repair_folds) and build
  // the shell over the repaired base. The relaxed vertices stay within repair_max_above shell
  // heights above the base as given and repair_max_below under it, and move by at most
  // repair_max_shift along it (these override fold_repair's bounds): the texture is placed
  // through the shell but seen over the base as given, and the check after embedding allows it
  // 1% of H under the base. Two rounds (the folded vertices and one ring): local.
  bool repair_folds = true;
  FoldRepairOptions fold_repair = [] {
    FoldRepairOptions o;
    o.max_rounds = 2;
    return o;
  }();
  double repair_max_above = 0.1;
  double repair_max_below = 0.005;
  double repair_max_shift = 1.0;
  // Per-region fallback: where no valid shell can be made (the faces around a vertex the
  // bounded repair leaves folded; the prisms still offending at offset_surface's height floor:
  // thin parts, parts a hair apart, a base through itself), those faces and exclusion_rings
  // rings of faces around them are left out of the shell and the map is built on the rest (up
  // to max_exclusion_attempts times); the caller places the texture over the faces left out
  // otherwise (see exclusion()). No valid shell without leaving out more than
  // max_excluded_share of the base's area throws TopologyError. false: any such base throws.
  bool exclude_regions = true;
  int exclusion_rings = 0;          // >= 0
  int max_exclusion_attempts = 8;   // >= 1
  double max_excluded_share = 0.5;  // in [0, 1]
};

// The faces of the base left out of the shell (ShellMapOptions::exclude_regions).
//   faces        input faces left out, ascending (empty when the shell covers the whole base)
//   fold_faces   of them, those left out where the base folds (no direction above a vertex's
//                faces, even after the bounded fold repair); the others where the shell stays
//                invalid at offset_surface's height floor (thin parts, parts a hair apart)
//   area_share   their share of the base's area, in [0, 1]
//   reason       why: the fold repair's or offset_surface's complaint that made the first cut
struct ShellExclusion {
  std::vector<int> faces;
  int fold_faces = 0;
  double area_share = 0.0;
  std::string reason;
};

struct ShellOptimizeOptions {
  int max_sweeps = 30;  // iteration budget (>= 0)
  // Stop when a sweep lowers the total stretch by less (relative). Measured: the sweeps' gains
  // halve each time, from 8e-4 to 2e-3 for the first (Spot, the ivy wall), so 5e-4 ends within
  // about that much of where 1e-4 ends, in a third of the sweeps.
  double tolerance = 5e-4;
  std::uint64_t seed = 1;     // random line-search directions
  int line_search_steps = 8;  // step sizes tried per direction and sign: L, L/2, ... (>= 1)
};

struct ShellOptimizeReport {
  double stretch_before = 0.0;
  double stretch_after = 0.0;
  int sweeps = 0;
  long long accepted_moves = 0;
  int num_colours = 0;  // independent sets updated in parallel
  int num_free_vertices = 0;
};

// The shell map. Vertices of the chart-split tet mesh: UV row j of the atlas is vertex j (its
// base corner, texture (u, v, 0)) and vertex m + j (its offset corner, texture (u, v, H)),
// m = #UV. Shell face f's prism (a row of faces(): the input's faces but those left out, see
// exclusion()) gives tets 3f, 3f + 1, 3f + 2, split like shell_tet_indices, so the shell tets
// are exactly those of shell_tetrahedra over faces() and texture tets of different charts are
// disjoint.
class ShellMap {
 public:
  // Builds atlas, offset surface and both tet meshes, over the whole base or, where no valid
  // shell exists there, over the base without the regions left out (exclusion()).
  //   V #V by 3 finite positions, F #F by 3 faces, counter-clockwise seen from outside
  // Throws InvalidInput for bad options or input (see offset_surface, texture_atlas);
  // TopologyError when no valid shell exists (even after a fold repair and leaving regions
  // out, if enabled; the message says why).
  ShellMap(const MatrixX3d& V, const MatrixX3i& F, const ShellMapOptions& options);

  // Normalised total stretch (Eq. 9, see tet_stretch.h) with the given evaluator, or with the
  // CPU one. >= 1; +infinity if a texture tet is inverted.
  double stretch(TetStretchEvaluator& evaluator) const;
  double stretch() const;

  // Random line search (Sander et al. 2001, as in section 3.2) on the (u, v) of the offset
  // corners that are not on a chart border or a base boundary (w stays H): each sweep visits
  // every free vertex once, colour by colour (vertices of one colour share no tet and move in
  // parallel), tries a random direction with steps +-L 2^-k (L the mean length of the
  // vertex's texture edges to other offset corners), and keeps the best step only if it lowers
  // the local stretch sum_t L2(t)^2 |T_s,t| of its tets (the total's normaliser is constant:
  // borders are fixed) with no texture tet inverted. Directions come from a SplitMix64 hash of
  // (seed, sweep, vertex): the result does not depend on the thread count. Full evaluations
  // (before, after each sweep) use `evaluator`.
  // Throws InvalidInput for bad options; DeviceError from the evaluator.
  ShellOptimizeReport optimize(TetStretchEvaluator& evaluator,
                               const ShellOptimizeOptions& options = {});

  // The shell base: the input, or the fold-repaired input (see fold_repair()); #V by 3.
  const MatrixX3d& base_vertices() const { return base_V_; }
  // The shell's faces: the input's without those left out, in input order (#F' by 3). Face
  // indices of the atlas, the tets and ShellEmbedding's local coordinates are rows of this.
  const MatrixX3i& faces() const { return F_; }
  // The shell face of input face f (-1 when it was left out), and the input face of each
  // shell face (#F').
  int shell_face(int f) const { return shell_face_[static_cast<size_t>(f)]; }
  const std::vector<int>& input_faces() const { return input_face_; }
  const ShellExclusion& exclusion() const { return exclusion_; }
  const OffsetSurface& offset() const { return offset_; }
  const TextureAtlas& atlas() const { return atlas_; }
  double height() const { return height_; }
  // Chart-split shell and texture tets (shell_V, texture_V, T), 2#UV vertices, 3#F tets.
  const StretchProblem& problem() const { return problem_; }
  // Per UV row: true when its offset corner is fixed (chart border or base boundary).
  const std::vector<char>& fixed() const { return fixed_; }
  // Vertices moved by the fold repair (empty when the input did not fold).
  const FoldRepair& fold_repair() const { return repair_; }

 private:
  // The constructor's steps, in order (V, F as given).
  void build_offset(const MatrixX3d& V, const MatrixX3i& F, const ShellMapOptions& options);
  void exclude_until_valid(const MatrixX3d& V, const MatrixX3i& F, const ShellMapOptions& options,
                           const OffsetOptions& oo, OffsetFailure& failure, OffsetPairCache& cache);
  void number_shell_faces(Eigen::Index num_faces);
  void build_problem(int num_vertices);
  void mark_fixed_corners(int num_vertices);

  MatrixX3d base_V_;
  MatrixX3i F_;
  std::vector<int> input_face_, shell_face_;
  ShellExclusion exclusion_;
  double height_ = 0.0;
  FoldRepair repair_;
  OffsetSurface offset_;
  TextureAtlas atlas_;
  StretchProblem problem_;
  std::vector<char> fixed_;
};

}  // namespace mq
