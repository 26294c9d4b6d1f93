// Swatch animation (issue 25; paper section 4's animated ivy: displacements in time applied in
// the local frame of each output vertex). A swatch given with frames (the same mesh, its vertices
// moved) moves the output with it, without a new synthesis: each output vertex takes the
// displacement of the point it came from in the swatch (SurfaceElement::source: a leaf's own
// vertex; on a stem, the swatch vine's cross-section at the same place along one swatch vine
// length, corrected to be continuous where lengths meet), turned from the swatch's frame
// into the output's where the vertex lies: the rotation that best fits the points around it in the
// swatch onto the same points in the output (Kabsch); under a size map scaled by their spread's
// ratio too. A leaf takes one such turn for all of it (it
// moves as one, also where the surface bent it), a stem one per cross-section, so that it sways
// about its own course over the surface. An element the local patches stitched of parts of several
// swatch copies (section 2.7) takes a turn per part, and the parts' displacements are blended
// over a few edges either side of the seam.
#pragma once

#include <cmath>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/settled_motion.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/quilt_elements.h"
#include "core/surface/surface_quilting.h"

namespace mq {

// One frame of a swatch animation: per element of the prepared swatch (prepare_swatch of the
// swatch at the output's scale, element order), #V(element) by 3 displacements in its synthesis
// frame, the frame's positions minus the swatch's.
struct SwatchMotion {
  std::vector<MatrixX3d> displacement;
};

// The motion of `frame`, the swatch with its vertices moved, from `swatch` (the swatch the quilt
// was made of), both scaled by `scale` (SurfaceQuiltingStats::swatch_scale). `name` names the
// frame's file in messages. Throws InvalidInput "NAME: PROBLEM" when the frame's faces or vertex
// count differ from the swatch's or a coordinate is not finite.
SwatchMotion swatch_motion(const TriMesh& swatch, const TriMesh& frame, double scale,
                           const std::string& name);

// The check swatch_motion makes first, alone (before a synthesis: nothing prepared). Throws as
// swatch_motion.
void check_swatch_frame(const TriMesh& swatch, const TriMesh& frame, const std::string& name);

// A planar quilt (quilt_plane's `layer`, in the swatch's own axes, and its sources) as a quilt
// over its own plane, for SwatchAnimation with `layer` as the rest: its elements in order, every
// vertex over a base of two triangles whose normal is `normal` (the layer's thickness axis).
SurfaceQuilt layer_quilt(const TriMesh& layer, const PlaneSources& sources, const Vector3d& normal);

// The output's vertices with their sources located on the swatch and their frames, made once;
// frame() is then a pass over the vertices per swatch frame.
class SwatchAnimation {
 public:
  // quilt: the synthesis, made with SurfaceQuiltingOptions::keep_sources; rest: embed_quilt's
  // output of it, kept: its QuiltEmbeddingStats::kept; swatch and scale as for swatch_motion.
  // Throws InvalidInput when an element kept has no sources (a method that does not keep them)
  // and InternalError when rest does not match kept.
  SwatchAnimation(const SurfaceQuilt& quilt, const std::vector<int>& kept, const TriMesh& rest,
                  const TriMesh& swatch, double scale);

  // Damps the elements that the frames' motions would make meet another element or cross
  // themselves (core/mesh/settled_motion: half their motion, else none), the same in every frame.
  void settle(const std::vector<SwatchMotion>& motions, SettledMotionStats* stats = nullptr);

  // rest with each vertex moved by its source's displacement in `motion`, turned into its frame
  // (and damped as settle decided). A vertex whose displacement is zero keeps its rest position
  // exactly (a frame equal to the swatch gives rest's bytes). Deterministic whatever the thread
  // count.
  TriMesh frame(const SwatchMotion& motion) const;

 private:
  // A point on a prepared swatch element: its face there and barycentric coordinates.
  struct Location {
    int face = 0;
    Vector3d barycentric = Vector3d::Zero();
  };
  MatrixX3d gather_sources(const SurfaceQuilt& quilt, const std::vector<int>& kept,
                           const PreparedSwatch& prepared);
  void locate_sources(const SwatchRepeat& repeat, const PreparedSwatch& prepared,
                      const MatrixX3d& source);
  void fit_frame(const MatrixX3d& source, const MatrixX3d& out, Eigen::Index v0, Eigen::Index n);
  void bend_with_surface(const SurfaceElement& e, const TriMesh& base, const MatrixX3d& normals,
                         Eigen::Index v0);
  void find_parts(const SurfaceQuilt& quilt, const std::vector<int>& kept, const MatrixX3d& source,
                  const std::vector<Eigen::Index>& first);
  void fit_parts(const MatrixX3d& source, const MatrixX3d& out, Eigen::Index v0, Eigen::Index n);
  void find_seams();
  void blend_seams(MatrixX3d& D) const;
  void fade_near_meetings(const std::vector<SwatchMotion>& motions);
  void fit_frames(const MatrixX3d& source, const MatrixX3d& out, Eigen::Index v0, Eigen::Index n,
                  double reach);
  MatrixX3d cross_sections(const SwatchMotion& motion) const;
  Vector3d displacement(const SwatchMotion& motion, const MatrixX3d& sections, size_t v) const;
  MatrixX3d positions(const SwatchMotion& motion, const std::vector<double>& amplitude) const;
  // The size of points in the output against theirs in the swatch from their weighted squared
  // spreads: 1 unless the quilt was made under a size map.
  double size_ratio(double spread_out, double spread_source) const {
    return sized_ && spread_source > 0 ? std::sqrt(spread_out / spread_source) : 1.0;
  }

  TriMesh rest_;
  std::vector<MatrixX3i> element_faces_;  // of the prepared swatch
  std::vector<int> element_;              // #V(rest): source element
  std::vector<int> part_;  // #V(rest): its part, moved as one copy (find_parts; else element_)
  std::vector<Location> location_;  // #V(rest): where, off the repeated element
  // The repeated element (the vine): #V(rest) places along one repeat in [0, 1) (-1 off it), and
  // its cross-sections: how many, and each swatch vine vertex's.
  SwatchRepeat repeat_;
  std::vector<double> along_;
  int repeat_bins_ = 0;
  std::vector<int> repeat_bin_;
  // #V(rest): swatch frame -> output frame; under a size map (SurfaceQuilt::sized) times the
  // element's size there against the swatch's, so that a smaller element moves less.
  std::vector<Eigen::Matrix3f> rotation_;
  bool sized_ = false;
  std::vector<int> component_;  // #V(rest): its element in rest (connected component)
  // Where stitched parts of different swatch elements meet (find_seams): the vertices within
  // kSeamRings edges of a seam (ascending) and each one's neighbours, blended over kSeamSteps.
  static constexpr int kSeamRings = 3, kSeamSteps = 32;
  struct Seams {
    std::vector<int> vertices;
    Adjacency neighbours;
  } seams_;
  std::vector<double> amplitude_;  // per element of rest: its motion's share (settle)
  // Threads stitched or welded of parts (SurfaceQuilt::stitched with long elements) are damped
  // where they would meet, all of them alike, fading with the distance (fade_near_meetings):
  // #V(rest) shares of each vertex's motion, or empty (1). The shell height scales the fade.
  bool fade_ = false;
  double shell_ = 0;
  std::vector<double> fade_share_;
  int faded_elements_ = 0;
};

}  // namespace mq
