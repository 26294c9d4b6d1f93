// Procedural sample swatches: flat, thin sheets of geometry elements like the input textures of
// mesh quilting (Zhou et al. 2006, Sec. 3: the swatch is a small planar sample an artist builds).
// Every generator returns a TriMesh with outward-oriented closed manifold components (one per
// element) placed with min corner at the origin: x-y is the footprint, z in [0, thickness].
// Output is deterministic for the given options (seeded std::mt19937_64, raw output only).
// Elements carry kinds (TriMesh::kinds): "ring"; "ring" and "connector"; "thread_x" and
// "thread_y"; "apple"; "vine" and "leaf".
#pragma once

#include <cstdint>

#include "core/mesh/mesh.h"

namespace mq {

struct ChainMailOptions {
  int rows = 6;               // rings per column (along y)
  int cols = 6;               // columns (along x)
  double ring_radius = 1.0;   // radius of the ring's wire centre circle
  double wire_radius = 0.12;  // must be <= 0.2 * ring_radius (ring clearance 0.5 * ring_radius)
  int ring_segments = 48;     // segments along the ring
  int wire_segments = 12;     // segments around the wire
};

// European 4-in-1 chain mail. Ring (c, k) (column c along x, k along y) is centred at
// (c * 1.25 R, (k + (c odd ? 0.5 : 0)) * 1.25 R) and tilted by 0.6 rad about the x axis, the
// tilt sign alternating between columns; each ring passes through its four diagonal neighbours
// in the adjacent columns and leans on its neighbours in the same column without touching them.
// Centre circles keep >= 0.5 R apart, so tubes with wire_radius <= 0.2 R never intersect.
// The sheet repeats with periods chainmail_period_x/y (two columns in x, one ring in y).
// rows * cols rings of 2 * ring_segments * wire_segments faces each (41k at the defaults).
// Larger sheet: raise rows/cols; smoother rings: raise ring_segments/wire_segments.
// Throws InvalidInput for counts < 1, segments < 3, non-positive radii or too thick a wire.
TriMesh chainmail_4in1(const ChainMailOptions& options = {});
double chainmail_period_x(const ChainMailOptions& options = {});  // 2.5 * ring_radius
double chainmail_period_y(const ChainMailOptions& options = {});  // 1.25 * ring_radius

struct SquareMailOptions {
  int rows = 6;               // flat rings per column (along y)
  int cols = 6;               // flat rings per row (along x)
  double ring_radius = 1.0;   // radius of a flat ring's wire centre circle
  double wire_radius = 0.12;  // of both kinds; must be <= 0.15 * ring_radius
  int ring_segments = 48;     // segments along a ring (connectors too)
  int wire_segments = 12;     // segments around the wire
};

// A square 4-in-1 sheet ("Japanese 4-in-1"): flat rings (kind "ring") in the z = 0 plane on a
// square grid of pitch 2.5 R, each pair of grid neighbours joined by an upright connector ring
// (kind "connector", radius 0.6 R) standing in the vertical plane through both centres, half-way
// between them. Each connector passes through the holes of its two flat rings 0.65 R from their
// centres, so an interior flat ring links 4 connectors and every connector 2 flat rings. With
// wire_radius <= 0.15 R every two wires keep >= 0.05 R apart (closest: a flat ring's wire
// through a connector's hole and the connector's wire through the ring's hole), so no rings
// intersect. Only connectors between two flat rings of the sheet are made: rows * cols flat rings
// and (rows - 1) * cols + rows * (cols - 1) connectors, all of 2 * ring_segments * wire_segments
// faces; flat rings first (row by row), then the connectors along x, then along y.
// The sheet repeats with period chainmail_square_period along x and y (one flat ring and two
// connectors per cell) and is symmetric under a half turn about a flat ring's centre.
// Throws InvalidInput for counts < 1, segments < 3, non-positive radii or too thick a wire.
TriMesh chainmail_square(const SquareMailOptions& options = {});
double chainmail_square_period(const SquareMailOptions& options = {});  // 2.5 * ring_radius

struct WeaveOptions {
  int threads_x = 6;            // threads running along x (warp), stacked along y
  int threads_y = 6;            // threads running along y (weft), stacked along x
  double spacing = 1.0;         // distance between parallel threads
  double thread_radius = 0.15;  // must be <= 0.17 * spacing
  int segments_per_cell = 16;   // segments along a thread per spacing
  int tube_segments = 10;       // segments around a thread
};

// Plain weave: warp j (y = j * spacing) has height (-1)^j A cos(pi x / spacing), weft i
// (x = i * spacing) the opposite sign, so at each crossing one passes over the other, alternating
// along every thread; A = 1.2 * thread_radius. Each thread is a closed tube with flat end caps
// spanning half a spacing beyond the outermost crossing. Threads never intersect.
// Larger cloth: raise threads_x/threads_y; smoother: raise segments_per_cell/tube_segments.
// Throws InvalidInput for counts < 1, too few segments, non-positive sizes or too thick a thread.
TriMesh plain_weave(const WeaveOptions& options = {});

struct AppleOptions {
  int count = 24;                  // number of apples
  double mean_radius = 1.0;        // mean apple radius
  double radius_variation = 0.25;  // radii uniform in mean_radius * [1 - v, 1 + v], v in [0, 0.9]
  uint64_t seed = 1;
  int resolution = 16;  // segments around an apple (>= 6); 352 faces per apple at 16
};

// One layer of apples resting on z = 0: each a closed surface of revolution with dimples at the
// bottom and top, a stem rising from the top dimple, five faint lobes at the bottom, and a random
// rotation about z. Placed by seeded dart throwing with non-overlapping bounding circles in a
// square grown until all fit, so no two apples intersect.
// More apples: raise count (the square grows); smoother: raise resolution.
// Throws InvalidInput for count < 1, resolution < 6, mean_radius <= 0 or variation outside [0,0.9].
TriMesh apple_layer(const AppleOptions& options = {});

struct IvyOptions {
  double length = 10.0;    // vine length along x
  int leaves = 12;         // number of leaves, alternating sides of the vine
  double leaf_size = 0.8;  // approximate leaf length
  uint64_t seed = 1;
};

// A wavy ivy vine (closed capped tube resting on z = 0) along x with five-lobed leaves, each a
// thin closed solid sloping gently from above the vine down to the plane, alternately on either
// side. Leaves are placed so they intersect neither the vine nor each other (rejection with the
// mesh intersection test). Longer section: raise length and leaves together.
// Throws InvalidInput for length <= 0, leaves < 0 or leaf_size <= 0.
TriMesh ivy_section(const IvyOptions& options = {});

// A looping wind animation of an ivy section (issue 25, a swatch animation to try): `frames`
// frames, each the section with its vertices moved (faces unchanged), frame 0 the section itself
// and the loop closing after the last. Each leaf turns rigidly about the line across its back
// (through its attachment, its vertex nearest the vine): its tip lifts by up to lift_angle and it
// rolls about its own axis by up to roll_share of that; the vine can sway sideways by up to
// vine_sway of its radius, carrying its leaves (0 by default: ivy holds to its wall by rootlets,
// and stems laid as closely as the vine method lays them would sway into their neighbours' leaves).
// A gust (sin^2 over the loop) runs along the vine as a wave of the section's length, so that
// sections laid end to end move as one. A leaf that would meet the vine or another leaf in some
// frame moves half as much, else not at all (settled_amplitudes).
struct IvyWindOptions {
  int frames = 24;
  double lift_angle = 0.35;  // radians
  double roll_share = 0.15;
  double vine_sway = 0;
};

// The ivy's longest element (along x) is its vine, every other element a leaf. Throws
// InvalidInput for frames < 1, a mesh of fewer than two elements, or negative amplitudes.
std::vector<TriMesh> ivy_wind(const TriMesh& ivy, const IvyWindOptions& options = {});

}  // namespace mq
