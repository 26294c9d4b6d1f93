// Threads that run on (issue 23): a periodic swatch whose elements are threads (a weave) cut
// into one-period pieces, the unit its lattice tiles, and pieces placed over a surface welded
// end to end into continuous threads.
//
// Why: such a swatch is periodic but not a lattice of separate elements (each thread runs its
// whole length, so its copies a period apart overlap), and quilting it in swatch-sized patches
// cuts every thread at every patch seam (on the cup and the bunny the median thread was exactly
// one swatch thread long). One period of a thread is a piece whose copies a period apart meet
// end to end; at a lattice cell's border they coincide, and across the seamless layout's cuts
// too, since its transitions are symmetries of the swatch. Welded there, a thread ends only
// where a piece could not be placed: at cones, borders and where its continuation would not fit.
#pragma once

#include <functional>
#include <vector>

#include "core/planar/quilt_elements.h"
#include "core/planar/swatch_symmetry.h"
#include "core/surface/surface_quilting.h"

namespace mq {

// One period of a thread of the swatch: an open tube between two boundary loops, its start
// loop at the cut plane and its end loop one period further along, where the next piece's
// start loop lies.
struct ThreadPiece {
  // #V by 3, synthesis frame: the tube's vertices, then the centres of the start and the end
  // loop (used by no face: the caps' apexes where a thread ends).
  MatrixX3d V;
  MatrixX3i F;   // #F by 3, the open tube, oriented outward like the swatch
  int kind = 0;  // the thread's kind (PreparedSwatch::kinds)
  // Boundary loops, each in the order of its boundary half-edges (start[i] -> start[i + 1] is
  // an edge of a face); end[i] = start[i] + period, so the end loop runs the other way round.
  std::vector<int> start, end;
  int start_centre = 0, end_centre = 0;  // rows of V
  Vector2d period = Vector2d::Zero();    // the lattice vector along the thread
  Vector2d centre = Vector2d::Zero();    // the footprint centre (mean x, y of the tube)
  int source = 0;                        // the swatch element it was cut from
};

// The pieces, one per lattice orbit of threads: their copies at every lattice translation are
// the swatch's texture, threads continued without end.
struct ThreadTiling {
  std::vector<ThreadPiece> pieces;
  bool empty() const { return pieces.empty(); }
};

// A quick necessary condition for thread_tiling, without the symmetry: at least 2 elements and
// most of them long (footprint at least 4 times longer than wide, and over 60% of the swatch
// along x or y).
bool long_elements(const PreparedSwatch& swatch);

// The thread pieces of a periodic swatch (`symmetry` as detect_swatch_symmetry finds it); empty
// when the swatch is not a lattice of threads: not periodic, an element that is not long, or
// one that is not invariant under a lattice vector along it, is too short to hold a period
// between its ends, or has no cross-section where a plane orthogonal to it cuts it cleanly
// along edges (a ring of vertices, as a swept tube has where it runs level: a weave's
// crossings) with a matching ring one period on. Of the clean cuts, one that the swatch's half
// turn maps onto a lattice copy of the piece (when any is: pieces then meet across the
// layout's half-turn transitions), and of those the one whose centre is farthest from other
// elements (an unwelded end is capped there). Deterministic. O(#F) per candidate cut, plus its
// distance to the swatch's other vertices.
ThreadTiling thread_tiling(const PreparedSwatch& swatch, const SwatchSymmetry& symmetry);

// The pieces at the detail of `detailed` (the swatch `full` they were cut from after
// reduce_element_detail, core/mesh/element_detail.h, elements in the same order): each piece's
// tube simplified to the share of faces its source element kept, its cut loops and their
// centres staying as they are, so the pieces still weld into threads. Pieces are cut at full
// detail because a simplified thread has no clean cross-section one period from another.
void reduce_piece_detail(ThreadTiling& tiling, const PreparedSwatch& full,
                         const PreparedSwatch& detailed);

// A piece placed over the surface: the copy of tiling.pieces[piece] in local coordinates (its
// vertices in the piece's order).
struct PlacedPiece {
  int piece = 0;
  SurfaceElement element;
};

// Two loops of placed pieces that coincide (loop 0 the start, 1 the end): a's loop vertex
// i is b's loop vertex (offset - i) mod n, the loops running opposite ways round.
struct ThreadWeld {
  int a = 0, loop_a = 0, b = 0, loop_b = 0;
  int offset = 0;
  double gap = 0;  // the largest distance between welded vertices (proxy positions)
};

// The loops that coincide, each welded at most once: candidates whose vertices all lie within
// `tolerance` times the loop's shortest edge of the other's (nearest first, one to one, in
// opposite order); where a loop has several, the smallest gap (ties by indices) wins.
//   position(k, v)  a 3D position (a proxy of the embedding) of vertex v of placed[k]
// Deterministic; O(loops log loops) with a grid over the loop centres.
std::vector<ThreadWeld> find_thread_welds(const std::vector<PlacedPiece>& placed,
                                          const ThreadTiling& tiling,
                                          const std::function<Vector3d(int, int)>& position,
                                          double tolerance = 0.5);

struct ThreadWeldStats {
  int threads = 0;         // elements made
  int closed_threads = 0;  // of them, closed on themselves (no end)
  int welds = 0;           // loops joined (in the threads made)
  int caps = 0;            // ends capped
  int short_threads = 0;   // chains of fewer than min_pieces pieces, left out
};

// The placed pieces joined at the welds into threads: one element per chain (or cycle) of
// welded pieces, the welded loops' vertices shared, every loop left open capped by a fan around
// its centre vertex, so each thread is one closed manifold tube (given pieces that are). Pieces
// with dropped[k] set are left out (their welds ignored). Threads are ordered by their lowest
// piece, which comes first in each. flat is left empty: a thread is no rigid shape. Chains of
// fewer than min_pieces pieces are left out.
//   face_piece (optional)  per thread, the placed piece of each of its faces (caps: their loop's)
// Deterministic.
std::vector<SurfaceElement> weld_threads(const std::vector<PlacedPiece>& placed,
                                         const ThreadTiling& tiling,
                                         const std::vector<ThreadWeld>& welds,
                                         const std::vector<char>& dropped,
                                         ThreadWeldStats* stats = nullptr,
                                         std::vector<std::vector<int>>* face_piece = nullptr,
                                         int min_pieces = 1);

}  // namespace mq
