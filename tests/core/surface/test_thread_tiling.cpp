// Threads that run on (core/surface/thread_tiling): a plain weave cut into one-period pieces that
// tile its lattice; pieces welded end to end into closed, manifold, outward threads; and the weave
// laid over generated bases through the global layout (core/surface/global_quilting): over a
// cylinder its threads run its whole length or close round it and end only at its borders, over a
// sphere they run many swatch threads long and end only at its four cones. Deterministic.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>

#include "core/mesh/element_detail.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/planar_quilting.h"
#include "core/planar/swatch_generators.h"
#include "core/shell/quilt_embedding.h"
#include "core/structure/texture_structure.h"
#include "core/surface/global_quilting.h"
#include "core/surface/tangent_field.h"
#include "core/surface/thread_tiling.h"
#include "tests/core/planar_checks.h"
#include "tests/core/shell_fixtures.h"
#include "tests/core/vine_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

constexpr int kTube = 6;   // segments round a thread
constexpr int kAlong = 8;  // segments along a thread per spacing

TriMesh weave() {
  WeaveOptions o;
  o.threads_x = o.threads_y = 4;
  o.tube_segments = kTube;
  o.segments_per_cell = kAlong;
  return plain_weave(o);
}

struct Detected {
  PreparedSwatch swatch;
  SwatchSymmetry symmetry;
};

Detected detect(const TriMesh& mesh) {
  Detected d;
  d.swatch = prepare_swatch(mesh);
  const SwatchFaceTree tree(d.swatch.mesh.V, d.swatch.mesh.F);
  d.symmetry = detect_swatch_symmetry(d.swatch, tree, matching_cell_size(d.swatch));
  return d;
}

double signed_volume(const MatrixX3d& V, const MatrixX3i& F) {
  double v = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    v += V.row(F(f, 0)).dot(V.row(F(f, 1)).cross(V.row(F(f, 2))));
  return v / 6;
}

// Every element of the mesh a closed manifold tube enclosing positive volume.
void expect_closed_outward_elements(const TriMesh& mesh) {
  std::vector<int> fc;
  const int n = connected_components(mesh.F, mesh.num_vertices(), fc);
  const std::vector<std::vector<int>> groups = component_faces(fc, n);
  int bad = 0;
  for (int c = 0; c < n; ++c) {
    const TriMesh part = extract_faces(mesh, groups[c]);
    const TopologyReport t = topology_report(part);
    if (!t.closed() || !t.manifold() || !(signed_volume(part.V, part.F) > 0)) ++bad;
  }
  EXPECT_EQ(bad, 0) << "of " << n << " elements";
}

TEST(ThreadTiling, AWeaveIsCutIntoOnePeriodPiecesOfEachThreadKind) {
  const Detected d = detect(weave());
  ASSERT_TRUE(d.symmetry.periodic);
  EXPECT_TRUE(long_elements(d.swatch));
  const ThreadTiling tiling = thread_tiling(d.swatch, d.symmetry);
  ASSERT_EQ(tiling.pieces.size(), 2u);  // every warp is a lattice copy of one, every weft too
  std::vector<std::string> kinds;
  for (const ThreadPiece& p : tiling.pieces) {
    kinds.push_back(d.swatch.kinds[static_cast<size_t>(p.kind)]);
    // One period: two spacings (the warps a spacing apart pass over and under alternately).
    EXPECT_NEAR(p.period.norm(), 2.0, 1e-6);
    EXPECT_EQ(p.F.rows(), 2 * kTube * 2 * kAlong);
    // A ring of the tube.
    const size_t loop = p.start.size();
    EXPECT_EQ(loop, static_cast<size_t>(kTube));
    ASSERT_EQ(p.end.size(), loop);
    for (size_t i = 0; i < p.start.size(); ++i) {
      const Vector3d shift = p.V.row(p.end[i]) - p.V.row(p.start[i]);
      EXPECT_LT((shift - Vector3d(p.period.x(), p.period.y(), 0)).norm(), 1e-6);
    }
    // An open tube: its only boundary is the two loops (an annulus: Euler characteristic 0).
    TriMesh tube;
    tube.V = p.V.topRows(p.V.rows() - 2);
    tube.F = p.F;
    const TopologyReport t = topology_report(tube);
    EXPECT_EQ(t.num_boundary_edges, 2 * static_cast<int>(loop));
    EXPECT_EQ(t.num_non_manifold_edges, 0);
    // Cut at a crossing, where the tube runs level and a plane cuts it along a ring (its
    // sloping rings between crossings lean off any plane across it), the thread 0.18 above or
    // below mid height.
    const Vector3d centre = p.V.row(p.start_centre);
    EXPECT_NEAR(std::abs(centre.z() - 0.5 * d.swatch.size.z()), 0.18, 1e-6);
    // The half turn maps the piece onto a lattice copy of itself: across a half-turn
    // transition of the layout the pieces on both sides meet end to end.
    Eigen::Matrix2d basis;
    basis.col(0) = d.symmetry.a;
    basis.col(1) = d.symmetry.b;
    ASSERT_TRUE(d.symmetry.half_turn);
    const Vector3d image0(d.symmetry.c.x() - p.V(0, 0), d.symmetry.c.y() - p.V(0, 1), p.V(0, 2));
    int best = 0;
    for (Eigen::Index w = 0; w < p.V.rows() - 2; ++w) {
      int matched = 0;
      const Vector3d shift = image0 - p.V.row(w).transpose();
      const Vector2d k = basis.inverse() * shift.head<2>();
      const Vector2d L = basis * Vector2d(std::round(k.x()), std::round(k.y()));
      if ((L - shift.head<2>()).norm() > 1e-5 || std::abs(shift.z()) > 1e-9) continue;
      for (Eigen::Index v = 0; v < p.V.rows() - 2; ++v) {
        const Vector3d q(d.symmetry.c.x() - p.V(v, 0) - L.x(), d.symmetry.c.y() - p.V(v, 1) - L.y(),
                         p.V(v, 2));
        bool hit = false;
        for (Eigen::Index u = 0; u < p.V.rows() - 2 && !hit; ++u)
          hit = (p.V.row(u).transpose() - q).norm() < 1e-5;
        matched += hit;
      }
      best = std::max(best, matched);
    }
    EXPECT_EQ(best, p.V.rows() - 2);
  }
  std::sort(kinds.begin(), kinds.end());
  EXPECT_EQ(kinds, (std::vector<std::string>{"thread_x", "thread_y"}));
}

// The pieces' lattice copies are the swatch's threads: every vertex of every thread (away from
// its capped ends) is a vertex of some copy.
TEST(ThreadTiling, PieceCopiesAreTheSwatchThreads) {
  const Detected d = detect(weave());
  const ThreadTiling tiling = thread_tiling(d.swatch, d.symmetry);
  ASSERT_FALSE(tiling.empty());
  Eigen::Matrix2d basis;
  basis.col(0) = d.symmetry.a;
  basis.col(1) = d.symmetry.b;
  int tested = 0, found = 0;
  for (const Element& e : d.swatch.elements) {
    for (Eigen::Index v = 0; v < e.V.rows(); ++v) {
      const Vector3d q = e.V.row(v);
      const Vector2d lo = e.lo + Vector2d::Constant(0.5), hi = e.hi - Vector2d::Constant(0.5);
      const bool along_x = e.hi.x() - e.lo.x() > e.hi.y() - e.lo.y();
      const double t = along_x ? q.x() : q.y();
      if (t < (along_x ? lo.x() : lo.y()) || t > (along_x ? hi.x() : hi.y())) continue;
      ++tested;
      bool hit = false;
      for (const ThreadPiece& p : tiling.pieces) {
        const Vector2d k = basis.inverse() * (q.head<2>() - p.centre);
        for (int j = static_cast<int>(std::floor(k.y())) - 3; j <= k.y() + 3 && !hit; ++j)
          for (int i = static_cast<int>(std::floor(k.x())) - 3; i <= k.x() + 3 && !hit; ++i) {
            const Vector2d L = basis * Vector2d(i, j);
            for (Eigen::Index w = 0; w < p.V.rows() - 2 && !hit; ++w)
              hit = (p.V.row(w).transpose() + Vector3d(L.x(), L.y(), 0) - q).norm() < 1e-6;
          }
      }
      found += hit;
    }
  }
  ASSERT_GT(tested, 1000);
  EXPECT_EQ(found, tested);
}

TEST(ThreadTiling, ChainMailApplesAndIvyAreNoThreads) {
  for (const TriMesh& m :
       std::vector<TriMesh>{test::tiny_chainmail(), apple_layer(), ivy_section()}) {
    const Detected d = detect(m);
    EXPECT_FALSE(long_elements(d.swatch));
    EXPECT_TRUE(thread_tiling(d.swatch, d.symmetry).empty());
  }
}

// Pieces placed by hand over a flat base, two meeting end to end and one apart: the two are
// welded into one thread (the shared loop once, caps at its two ends), the third capped alone;
// each a closed, manifold tube enclosing positive volume.
// Three copies of the first piece, two of them one period apart, welded: two closed threads.
void expect_pieces_weld(const ThreadTiling& tiling) {
  const ThreadPiece& p = tiling.pieces[0];
  // One large triangle under everything: local coordinates are its barycentric weights.
  TriMesh base;
  base.V.resize(3, 3);
  base.V << -100, -100, 0, 100, -100, 0, -100, 100, 0;
  base.F.resize(1, 3);
  base.F << 0, 1, 2;
  const auto place = [&](double shift) {
    PlacedPiece pp;
    pp.piece = 0;
    pp.element.F = p.F;
    pp.element.kind = p.kind;
    pp.element.face.assign(static_cast<size_t>(p.V.rows()), 0);
    pp.element.barycentric.resize(p.V.rows(), 3);
    pp.element.height.resize(p.V.rows());
    for (Eigen::Index v = 0; v < p.V.rows(); ++v) {
      const Vector2d x = p.V.row(v).head<2>().transpose() + shift * p.period;
      const double b1 = (x.x() + 100) / 200, b2 = (x.y() + 100) / 200;
      pp.element.barycentric.row(v) << 1 - b1 - b2, b1, b2;
      pp.element.height(v) = p.V(v, 2);
    }
    return pp;
  };
  const std::vector<PlacedPiece> placed{place(0), place(1), place(3)};
  const auto position = [&](int k, int v) -> Vector3d {
    const SurfaceElement& e = placed[static_cast<size_t>(k)].element;
    const Vector3d b = e.barycentric.row(v).transpose();
    return b(0) * base.V.row(0).transpose() + b(1) * base.V.row(1).transpose() +
           b(2) * base.V.row(2).transpose() + Vector3d(0, 0, e.height(v));
  };
  const std::vector<ThreadWeld> welds = find_thread_welds(placed, tiling, position);
  ASSERT_EQ(welds.size(), 1u);
  EXPECT_EQ(welds[0].a, 0);
  EXPECT_EQ(welds[0].loop_a, 1);
  EXPECT_EQ(welds[0].b, 1);
  EXPECT_EQ(welds[0].loop_b, 0);
  EXPECT_LT(welds[0].gap, 1e-6);
  ThreadWeldStats stats;
  const std::vector<SurfaceElement> threads = weld_threads(placed, tiling, welds, {}, &stats);
  ASSERT_EQ(threads.size(), 2u);
  EXPECT_EQ(stats.welds, 1);
  EXPECT_EQ(stats.caps, 4);
  EXPECT_EQ(stats.closed_threads, 0);
  const int tube = static_cast<int>(p.V.rows()) - 2;
  EXPECT_EQ(threads[0].face.size(), static_cast<size_t>(2 * tube - kTube + 2));
  EXPECT_EQ(threads[0].F.rows(), 2 * p.F.rows() + 2 * kTube);
  EXPECT_EQ(threads[1].face.size(), static_cast<size_t>(tube + 2));
  for (const SurfaceElement& e : threads) {
    TriMesh m;
    m.F = e.F;
    m.V.resize(static_cast<Eigen::Index>(e.face.size()), 3);
    for (size_t v = 0; v < e.face.size(); ++v) {
      const Vector3d b = e.barycentric.row(static_cast<Eigen::Index>(v)).transpose();
      m.V.row(static_cast<Eigen::Index>(v)) =
          (b(0) * base.V.row(0).transpose() + b(1) * base.V.row(1).transpose() +
           b(2) * base.V.row(2).transpose() +
           Vector3d(0, 0, e.height(static_cast<Eigen::Index>(v))))
              .transpose();
    }
    const TopologyReport t = topology_report(m);
    EXPECT_EQ(t.num_components, 1);
    EXPECT_TRUE(t.closed());
    EXPECT_TRUE(t.manifold());
    EXPECT_GT(signed_volume(m.V, m.F), 0);
    EXPECT_TRUE(self_intersecting_components(m.V, m.F).empty());
  }
  // A piece left out ends the thread there; single pieces can be left out too.
  EXPECT_EQ(weld_threads(placed, tiling, welds, {0, 1, 0}, &stats).size(), 2u);
  EXPECT_EQ(stats.caps, 4);
  EXPECT_EQ(weld_threads(placed, tiling, welds, {}, &stats, nullptr, 2).size(), 1u);
  EXPECT_EQ(stats.short_threads, 1);
}

TEST(ThreadTiling, WeldedPiecesAreOneClosedManifoldThread) {
  const Detected d = detect(weave());
  const ThreadTiling tiling = thread_tiling(d.swatch, d.symmetry);
  ASSERT_FALSE(tiling.empty());
  expect_pieces_weld(tiling);
}

// At lower detail (--detail, issue 26's Preview) the pieces are cut at full detail and then
// simplified with their cut loops kept: they weld as before, into closed threads that do not
// intersect themselves.
TEST(ThreadTiling, PiecesAtLowerDetailStillWeld) {
  const TriMesh mesh = weave();
  const Detected d = detect(mesh);
  ElementDetailOptions o;
  o.detail = 0.3;
  const PreparedSwatch low = prepare_swatch(reduce_element_detail(mesh, o).mesh);
  ThreadTiling tiling = thread_tiling(d.swatch, d.symmetry);
  ASSERT_FALSE(tiling.empty());
  const ThreadTiling full = tiling;
  reduce_piece_detail(tiling, d.swatch, low);
  ASSERT_EQ(tiling.pieces.size(), full.pieces.size());
  for (size_t i = 0; i < tiling.pieces.size(); ++i) {
    const ThreadPiece &a = full.pieces[i], &b = tiling.pieces[i];
    EXPECT_LT(b.F.rows(), 0.45 * static_cast<double>(a.F.rows())) << i;
    ASSERT_EQ(b.start.size(), a.start.size());
    for (size_t k = 0; k < a.start.size(); ++k) {  // the cut loops where they were
      EXPECT_EQ(b.V.row(b.start[k]), a.V.row(a.start[k]));
      EXPECT_EQ(b.V.row(b.end[k]), a.V.row(a.end[k]));
    }
    EXPECT_EQ(b.V.row(b.start_centre), a.V.row(a.start_centre));
    EXPECT_EQ(b.V.row(b.end_centre), a.V.row(a.end_centre));
  }
  expect_pieces_weld(tiling);
}

struct WeaveRun {
  SurfaceQuiltingStats stats;
  GlobalQuiltingStats global;
  QuiltEmbeddingStats embedding;
  TriMesh output;
  StructureSummary structure;
  bool used_global = false;
};

// The weave at `spacing` base units between threads, method auto, embedded by normal
// displacement (the layout decides the threads; the shell map is tested on its own).
WeaveRun run_weave(const TriMesh& base, double spacing, const MatrixX3d& field = MatrixX3d()) {
  WeaveRun r;
  const TriMesh swatch = weave();
  const double diagonal = bounding_box(base.V, base.F).extent().norm();
  SurfaceQuiltingOptions o;
  o.scale = spacing * bounding_box(swatch.V).extent().head<2>().maxCoeff() / diagonal;
  o.field = field;
  o.global.drop_folded_pieces = true;
  TranslationCostCpu cost;
  const SurfaceQuilt quilt =
      quilt_surface_auto(base, swatch, o, cost, &r.stats, &r.global, nullptr, &r.used_global);
  QuiltEmbeddingOptions e;
  e.shell_map = false;
  TetStretchCpu stretch;
  r.output = embed_quilt(quilt, e, stretch, &r.embedding);
  r.structure = summarize_structure(r.output, swatch, &base, r.stats.swatch_scale);
  return r;
}

void report(const char* what, const WeaveRun& r) {
  const StructureReport& s = r.structure.output;
  std::printf(
      "[ measure  ] %s: %d threads (%d closed), median %.1f swatch threads, %d interior ends, "
      "%d pieces (%d off, %d distorted, %d near cones, %d intersecting), %d welds, %d cones, "
      "coverage %.3f\n",
      what, s.long_elements, s.closed_long_elements, r.structure.comparison.long_length_ratio,
      s.interior_ends, r.global.thread_pieces, r.global.off_surface, r.global.pieces_distorted,
      r.global.pieces_near_cones, r.global.pieces_intersecting, r.global.thread_welds,
      r.global.singular_vertices, r.embedding.coverage);
}

void expect_whole_threads(const WeaveRun& r) {
  EXPECT_TRUE(r.used_global);
  EXPECT_TRUE(r.global.threads);
  EXPECT_EQ(r.embedding.removed_intersecting + r.embedding.removed_self_intersecting, 0);
  EXPECT_TRUE(intersecting_face_pairs(r.output.V, r.output.F).empty());
  EXPECT_TRUE(self_intersecting_components(r.output.V, r.output.F).empty());
  expect_closed_outward_elements(r.output);
  EXPECT_GE(r.embedding.coverage, 0.95);
}

// Under a region (a mask: a disk on a plane) threads end at its border, capped, instead of
// running on whole past it: nothing lies beyond it by more than a period (a piece is left out when
// most of it lies outside), and the threads are whole tubes.
TEST(ThreadTiling, ThreadsEndAtTheRegionsBorder) {
  const TriMesh base = test::plane_grid(10, 10, 40, 40);
  const TriMesh swatch = weave();
  const double spacing = 0.35;
  SurfaceQuiltingOptions o;
  o.scale = spacing * bounding_box(swatch.V).extent().head<2>().maxCoeff() /
            bounding_box(base.V, base.F).extent().norm();
  o.field = tangent_field_from_direction(base.V, base.F, Vector3d::UnitX());
  const auto radius = [](const Vector3d& p) { return std::hypot(p.x() - 5, p.y() - 5); };
  o.region = test::centroid_region([&](const Vector3d& c) { return radius(c) < 3; });

  TranslationCostCpu cost;
  SurfaceQuiltingStats stats;
  GlobalQuiltingStats global;
  const SurfaceQuilt quilt = quilt_surface_global(base, swatch, o, cost, &stats, &global);
  ASSERT_TRUE(global.threads);
  QuiltEmbeddingOptions e;
  e.shell_map = false;
  TetStretchCpu stretch;
  const TriMesh out = embed_quilt(quilt, e, stretch);
  double farthest = 0;
  for (int v = 0; v < out.num_vertices(); ++v)
    farthest = std::max(farthest, radius(out.V.row(v).transpose()));
  EXPECT_LT(farthest, 3 + 2 * spacing);  // a period is two thread spacings of the weave
  EXPECT_GT(farthest, 3 - spacing);      // and the disk is filled to its border
  EXPECT_GT(quilt.elements.size(), 20u);
  expect_closed_outward_elements(out);
  EXPECT_TRUE(intersecting_face_pairs(out.V, out.F).empty());
}

// Along the axis of an open cylinder: the warps run its whole height, the wefts close round it;
// nothing ends but at the two border circles (within a period of them: a piece that would
// reach beyond the border is left out whole).
TEST(ThreadTiling, OverACylinderThreadsRunItsLengthAndCloseRoundIt) {
  const TriMesh base = test::open_cylinder(2.0, 6.0, 64, 24);
  const double spacing = 0.35;
  const WeaveRun r =
      run_weave(base, spacing, tangent_field_from_direction(base.V, base.F, Vector3d::UnitZ()));
  report("cylinder", r);
  expect_whole_threads(r);
  const StructureReport& s = r.structure.output;
  EXPECT_EQ(r.global.singular_vertices, 0);
  EXPECT_GT(s.interior_ends, 0);  // within 5 thread widths of the border: the measure's margin
  StructureOptions near_border;
  near_border.automatic_border = false;
  near_border.border = mesh_border(base.V, base.F);
  near_border.end_margin = 2.5 * spacing;  // a period and a little
  EXPECT_EQ(measure_structure(r.output, near_border).interior_ends, 0);
  EXPECT_GT(s.closed_long_elements, 10);  // wefts round it, 36 spacings long
  // Warps: the height is 17 spacings, 3.8 swatch threads.
  EXPECT_GE(r.structure.comparison.long_length_ratio, 3.0);
}

// A sphere's four cones: the threads end only there, and run many swatch threads long.
TEST(ThreadTiling, OverASphereThreadsEndOnlyAtItsCones) {
  TriMesh base = test::icosphere(4);
  base.V *= 3.0;
  const WeaveRun r = run_weave(base, 0.3);
  report("sphere", r);
  expect_whole_threads(r);
  EXPECT_EQ(r.global.singular_vertices, 4);
  EXPECT_GE(r.structure.comparison.long_length_ratio, 3.0);
  // Every end is where a piece next to a cone was left out.
  EXPECT_LE(r.global.thread_ends, 2 * (r.global.pieces_near_cones + r.global.pieces_distorted +
                                       r.global.pieces_intersecting));
  EXPECT_GT(r.global.closed_threads, 0);
}

// --method auto: the global layout's thread tiling for the weave, its lattice placement for
// chain mail, the paper's patches for apples and ivy.
TEST(ThreadTiling, AutoTakesThreadsForTheWeaveOnly) {
  const TriMesh base = test::plane_grid(8, 8, 16, 16);
  const MatrixX3d field = tangent_field_from_direction(base.V, base.F, Vector3d::UnitX());
  struct Case {
    const char* name;
    TriMesh swatch;
    bool global, threads, tiled;
  };
  for (const Case& c : {Case{"weave", weave(), true, true, false},
                        Case{"chain mail", test::tiny_chainmail(), true, false, true},
                        Case{"apples", apple_layer(), false, false, false},
                        Case{"ivy", ivy_section(), false, false, false}}) {
    SCOPED_TRACE(c.name);
    SurfaceQuiltingOptions o;
    o.scale = 0.3;
    o.field = field;
    TranslationCostCpu cost;
    GlobalQuiltingStats g;
    bool global = false;
    quilt_surface_auto(base, c.swatch, o, cost, nullptr, &g, nullptr, &global);
    EXPECT_EQ(global, c.global);
    if (!global) continue;
    EXPECT_EQ(g.threads, c.threads);
    EXPECT_EQ(g.tiled, c.tiled);
  }
}

TEST(ThreadTiling, SameInputSameBytesWhateverTheThreadCount) {
  TriMesh base = test::icosphere(3);
  base.V *= 2.0;
  std::vector<TriMesh> outs;
  for (const int threads : {1, 2}) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    outs.push_back(run_weave(base, 0.3).output);
  }
  ASSERT_GT(outs[0].num_faces(), 0);
  EXPECT_EQ(outs[0].V, outs[1].V);
  EXPECT_EQ(outs[0].F, outs[1].F);
}

}  // namespace
}  // namespace mq
