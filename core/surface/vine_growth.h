// Ivy that grows (issue 23, item 4): a swatch made of one vine with compact elements (leaves)
// along it is laid over a surface as stems many swatch vines long that follow the guidance field,
// with the swatch's leaves along them at the swatch's leaves per vine length.
//
// Beyond the paper. Its local patches (section 3.1) place swatch copies side by side and never
// join their vines: every vine came out exactly one swatch vine long (the ivy wall: 4,297 pieces,
// 54% covered). Here the layout is grown, not matched:
//  1. Stems are streamlines of the guidance field on the base, evenly spaced in the manner of
//     Jobard and Lefer (1997), traced face by face with the direction carried across edges by
//     unfolding (so a stem bends over a box's edge as a straight line on the unfolded surface)
//     and turning towards the field no sharper than a set radius.
//  2. Each stem is one closed tube: the swatch vine's cross-section (radius, segments) swept
//     along the streamline, its centreline wave (the swatch vine's own, made periodic by a
//     cubic blend so that consecutive swatch lengths join smoothly) repeated along it.
//  3. The swatch's leaves are copied along the stems at the places its vine carries them,
//     repeated every swatch vine length, each laid rigidly from its attachment point by a
//     geodesic polar map (bent only by the surface); a leaf that would intersect anything
//     placed is tried a little along the stem, else left out.
// Under a size map (SurfaceQuiltingOptions::size_map, issue 25) every distance of the three steps
// is taken times the size asked where it is measured: stems closer where the map asks smaller
// elements, their tubes thinner and their pattern shorter there, leaves smaller.
// Every element is stored in local coordinates over the base (SurfaceElement), so the shell map
// and the post-processing apply as to the other methods.
#pragma once

#include "core/surface/surface_quilting.h"

namespace mq {

struct VineGrowthOptions {
  // Without a guidance field (SurfaceQuiltingOptions::field empty) stems climb along this world
  // direction projected onto the surface, turning towards it in proportion to the projection's
  // length, so that they run on straight where it is normal to the surface (across the top of a
  // wall). +Y: the up axis of OBJ, PLY and glTF files as Blender's exporters and scanners write
  // them (the shared bases are so). A given field is followed at full strength everywhere.
  Vector3d up = Vector3d::UnitY();
  // Distance between neighbouring stems in units of the closest two straight stems side by
  // side, in phase, can lie without touching (measured on the swatch's own geometry, where
  // each leaf of one lies between two of the other's). A little over 1 leaves room for the
  // surface's curvature: ivy wall (sample ivy swatch) at 1.0 24% of the leaves found no place,
  // at 1.03 4% (81% covered), at 1.1 4% (78% covered).
  double spacing = 1.03;
  // A stem ends where it comes closer to another than this fraction of the spacing (Jobard and
  // Lefer's d_test), and never closer than twice its tube's lateral extent.
  double stop_fraction = 0.6;
  // The sharpest turn of a stem following the field, as a radius in swatch vine lengths.
  double turn_radius = 0.5;
  // Streamlines shorter than this many swatch vine lengths are not grown.
  double min_length = 0.5;
};

struct VineGrowthStats {
  int stems = 0;              // stems grown (one element each)
  int streamlines_short = 0;  // traced but shorter than min_length: not grown
  int stems_cut = 0;          // would intersect an earlier stem or themselves: cut there
  int stems_dropped = 0;      // pieces still intersecting after the last round: left out
  int leaves = 0;             // compact elements placed along the stems
  int leaf_slots = 0;         // places the swatch's ratio gives along the stems (and up to
                              // the largest move past their ends)
  int leaves_shifted = 0;     // of the placed, moved along the stem to clear a neighbour
  double vine_length = 0;     // one swatch vine's length along its axis, base units (at full
                              // size under a size map)
  double spacing = 0;         // between stems, base units (at full size)
  double total_length = 0;    // of the stems, base units
  // Of the stems, in swatch vine lengths at the size asked along them (under a size map a
  // stem at half size is twice as many swatch vines long as its length at full size).
  double total_vines = 0;
  double median_length = 0;  // of the stems, in swatch vine lengths at the size asked
};

// Whether the prepared swatch is a vine with attached elements: exactly one long element (its
// graph-diameter length at least 4 times its width, the area over pi times that length, and at
// least half the footprint's longer side) and at least one other element, every other element
// compact (not long) and attached to it (within a quarter of its own footprint diameter of the
// long element's vertices). The ivy section is; chain mail, the weave and apples are not.
bool is_vine_swatch(const PreparedSwatch& swatch);

// Grows the swatch's vine over the base as described above; the result is like quilt_surface's
// (local coordinates on the refined base, kinds the swatch's). `stats` receives the preparation
// figures, iterations = stems and counts.added = elements. Deterministic whatever the thread
// count. Throws what quilt_surface throws, and InvalidInput for a swatch that is not a vine
// (is_vine_swatch), non-positive or non-finite growth options, or an output estimated above
// options.max_faces.
SurfaceQuilt quilt_surface_vines(const TriMesh& base, const TriMesh& swatch,
                                 const SurfaceQuiltingOptions& options,
                                 const VineGrowthOptions& vine_options = {},
                                 SurfaceQuiltingStats* stats = nullptr,
                                 VineGrowthStats* vine_stats = nullptr,
                                 ProgressSink* progress = nullptr);

// The same on a job prepare_surface_job made with the same options (`stats`: its figures so
// far). Throws like quilt_surface_vines.
SurfaceQuilt quilt_prepared_vines(SurfaceJob job, SurfaceQuiltingStats stats,
                                  const SurfaceQuiltingOptions& options,
                                  const VineGrowthOptions& vine_options,
                                  SurfaceQuiltingStats* stats_out = nullptr,
                                  VineGrowthStats* vine_stats = nullptr,
                                  ProgressSink* progress = nullptr);

}  // namespace mq
