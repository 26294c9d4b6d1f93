#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "core/planar/translation_cost.h"
#include "core/shell/quilt_embedding.h"
#include "core/shell/swatch_animation.h"
#include "core/surface/global_quilting.h"
#include "core/surface/vine_growth.h"
#include "tests/core/vine_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

using test::ivy_swatch;

// The vertices of each connected component of m.
std::vector<std::vector<int>> component_vertices(const TriMesh& m) {
  std::vector<int> fc;
  const int n = connected_components(m.F, m.num_vertices(), fc);
  std::vector<std::vector<int>> out(static_cast<size_t>(n));
  std::vector<int> of(static_cast<size_t>(m.num_vertices()), -1);
  for (int f = 0; f < m.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) of[static_cast<size_t>(m.F(f, k))] = fc[static_cast<size_t>(f)];
  for (int v = 0; v < m.num_vertices(); ++v)
    if (of[static_cast<size_t>(v)] >= 0)
      out[static_cast<size_t>(of[static_cast<size_t>(v)])].push_back(v);
  return out;
}

// The largest relative change of an edge's length from a to b (same faces).
double edge_strain(const MatrixX3d& a, const MatrixX3d& b, const MatrixX3i& F,
                   const std::vector<char>* faces = nullptr) {
  double worst = 0;
  for (int f = 0; f < F.rows(); ++f) {
    if (faces && !(*faces)[static_cast<size_t>(f)]) continue;
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k), j = F(f, (k + 1) % 3);
      const double la = (a.row(i) - a.row(j)).norm(), lb = (b.row(i) - b.row(j)).norm();
      worst = std::max(worst, std::abs(lb - la) / la);
    }
  }
  return worst;
}

TEST(IvyWind, LoopsLiftsTheLeavesAndKeepsEverythingApart) {
  const TriMesh ivy = ivy_swatch();
  IvyWindOptions o;
  o.frames = 12;
  const std::vector<TriMesh> frames = ivy_wind(ivy, o);
  ASSERT_EQ(frames.size(), 12u);
  EXPECT_TRUE(frames[0].V == ivy.V);  // frame 0 is the section, bit for bit
  const double height = ivy.V.col(2).maxCoeff();
  double lifted = 0;
  IntersectionOptions all;
  all.between_components_only = false;
  for (const TriMesh& f : frames) {
    EXPECT_TRUE(f.F == ivy.F);
    EXPECT_TRUE(f.face_kind == ivy.face_kind);
    EXPECT_GE(f.V.col(2).minCoeff(), -1e-12);  // nothing under the plane it rests on
    EXPECT_TRUE(intersecting_face_pairs(f.V, f.F, all).empty());
    // Leaves turn rigidly and the vine holds still: no edge changes length beyond rounding.
    EXPECT_LT(edge_strain(ivy.V, f.V, ivy.F), 1e-9);
    lifted = std::max(lifted, f.V.col(2).maxCoeff() - height);
  }
  // Mid-loop the gust lifts leaf tips well above the section's own height.
  EXPECT_GT(lifted, 0.5 * height);
  // Frames near the loop's ends are near the section (it closes smoothly).
  EXPECT_LT((frames[1].V - ivy.V).rowwise().norm().maxCoeff(),
            (frames[6].V - ivy.V).rowwise().norm().maxCoeff());
  EXPECT_THROW(ivy_wind(ivy, IvyWindOptions{0}), InvalidInput);
}

struct Animated {
  SurfaceQuilt quilt;
  TriMesh rest;
  QuiltEmbeddingStats embedding;
  double scale = 0;
};

// Ivy grown over an upright plane with its sources kept, embedded as the tool does.
Animated grow_ivy(const TriMesh& swatch, const Eigen::VectorXd& size_map = {}) {
  SurfaceQuiltingOptions o;
  o.scale = 0.1;  // the swatch's size as at 0.06 on a 2 x 1.5 plane (a third of the work)
  o.keep_sources = true;
  o.size_map = size_map;
  Animated a;
  SurfaceQuiltingStats stats;
  a.quilt = quilt_surface_vines(test::plane_grid(1.2, 0.9, 12, 9), swatch, o, {}, &stats);
  a.scale = stats.swatch_scale;
  TetStretchCpu stretch;
  a.rest = embed_quilt(a.quilt, {}, stretch, &a.embedding);
  return a;
}

// The vine swaying too (the cross-sections' path), or only the leaves (the default wind).
class SwatchAnimationSway : public ::testing::TestWithParam<double> {};

TEST_P(SwatchAnimationSway, IvyOnAPlaneMovesWithItsSwatch) {
  const TriMesh swatch = ivy_swatch();
  IvyWindOptions wind;
  wind.frames = 8;
  wind.vine_sway = GetParam();
  const std::vector<TriMesh> frames = ivy_wind(swatch, wind);
  const Animated a = grow_ivy(swatch);
  ASSERT_GT(a.rest.num_faces(), 0);
  SwatchAnimation animation(a.quilt, a.embedding.kept, a.rest, swatch, a.scale);
  std::vector<SwatchMotion> motions;
  double largest = 0;  // the swatch's largest vertex motion, at the output's scale
  for (size_t k = 0; k < frames.size(); ++k) {
    motions.push_back(swatch_motion(swatch, frames[k], a.scale, "frame"));
    largest = std::max(largest, (frames[k].V - swatch.V).rowwise().norm().maxCoeff() * a.scale);
  }
  SettledMotionStats settled;
  animation.settle(motions, &settled);
  const auto elements = component_vertices(a.rest);
  // Most elements move freely: on a plane nothing is bent, and leaves lift clear of their
  // neighbours.
  EXPECT_LT(settled.damped + settled.stilled, static_cast<int>(elements.size()) / 10)
      << settled.damped << " damped, " << settled.stilled << " still of " << elements.size();
  IntersectionOptions all;
  all.between_components_only = false;
  double moved = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    const TriMesh f = animation.frame(motions[k]);
    ASSERT_TRUE(f.F == a.rest.F);
    EXPECT_TRUE(f.face_kind == a.rest.face_kind);
    if (k == 0) {
      EXPECT_TRUE(f.V == a.rest.V);  // frame 0 is the static output, bit for bit
    }
    const double step = (f.V - a.rest.V).rowwise().norm().maxCoeff();
    moved = std::max(moved, step);
    // Each vertex moves as far as its source does, and where stems' repeats meet up to three
    // times that (the periodic correction adds the difference of two sources).
    EXPECT_LE(step, 3 * largest + 1e-12);
    EXPECT_TRUE(intersecting_face_pairs(f.V, f.F, all).empty()) << "frame " << k;
    // Leaves move as one (rigidly, or at half their motion: shrunk by cos(angle / 2), under 2%);
    // a swaying stem's cross-sections move whole, sheared as little as the swatch's own vine
    // (under 5%: its sway follows x, its rings lie across the wave).
    EXPECT_LT(edge_strain(a.rest.V, f.V, a.rest.F), GetParam() > 0 ? 0.05 : 0.02) << "frame " << k;
  }
  EXPECT_GT(moved, 0.3 * largest);
}

INSTANTIATE_TEST_SUITE_P(LeavesOrAll, SwatchAnimationSway, ::testing::Values(0.0, 0.5));

// Under a size map (issue 25) an element moves at its own size: the swatch lifted as a whole
// lifts the half-size ivy on the plane's right half as far as the full-size ivy on its left.
TEST(SwatchAnimation, ElementsMoveAtTheSizeTheMapGaveThem) {
  const TriMesh plane = test::plane_grid(1.2, 0.9, 12, 9);
  Eigen::VectorXd map(plane.num_vertices());
  for (int v = 0; v < plane.num_vertices(); ++v) map(v) = plane.V(v, 0) < 0.5 ? 1.0 : 0.5;
  const TriMesh swatch = ivy_swatch();
  const Animated a = grow_ivy(swatch, map);
  TriMesh lifted = swatch;
  lifted.V.col(2).array() += 0.2 * (swatch.V.col(2).maxCoeff() - swatch.V.col(2).minCoeff());
  const SwatchMotion motion = swatch_motion(swatch, lifted, a.scale, "lifted");
  const double lift = motion.displacement.front().row(0).norm();  // the swatch's, to scale
  SwatchAnimation animation(a.quilt, a.embedding.kept, a.rest, swatch, a.scale);
  const TriMesh f = animation.frame(motion);
  std::vector<double> left, right;
  for (const std::vector<int>& vertices : component_vertices(a.rest)) {
    double x = 0, moved = 0;
    for (const int v : vertices) {
      x += a.rest.V(v, 0) / static_cast<double>(vertices.size());
      moved += (f.V.row(v) - a.rest.V.row(v)).norm() / static_cast<double>(vertices.size());
    }
    if (x < 0.4) left.push_back(moved / lift);
    if (x > 0.6) right.push_back(moved / lift);
  }
  ASSERT_GT(left.size(), 5u);
  ASSERT_GT(right.size(), 5u);
  std::printf(
      "[ measure  ] lifted swatch under a size map: elements moved %.3f (left, size 1) and "
      "%.3f (right, size 0.5) of the swatch's lift\n",
      test::median(left), test::median(right));
  EXPECT_NEAR(test::median(left), 1.0, 0.05);
  EXPECT_NEAR(test::median(right), 0.5, 0.05);
}

TEST(SwatchAnimation, SameFramesWhateverTheThreadCount) {
  const TriMesh swatch = ivy_swatch();
  IvyWindOptions wind;
  wind.frames = 4;
  const std::vector<TriMesh> frames = ivy_wind(swatch, wind);
  std::vector<TriMesh> out[2];
  for (const int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    const Animated a = grow_ivy(swatch);
    SwatchAnimation animation(a.quilt, a.embedding.kept, a.rest, swatch, a.scale);
    std::vector<SwatchMotion> motions;
    for (const TriMesh& f : frames) motions.push_back(swatch_motion(swatch, f, a.scale, "f"));
    animation.settle(motions);
    for (const SwatchMotion& m : motions) out[threads - 1].push_back(animation.frame(m));
  }
  for (size_t k = 0; k < frames.size(); ++k) EXPECT_TRUE(out[0][k].V == out[1][k].V);
}

// `swatch` quilted over `base` at `scale` with its sources kept, by the global layout or the local
// patches, embedded as the tool does; *global_stats (optional) the layout's figures.
Animated quilt_with_sources(const TriMesh& base, const TriMesh& swatch, double scale, bool global,
                            GlobalQuiltingStats* global_stats = nullptr) {
  SurfaceQuiltingOptions o;
  o.scale = scale;
  o.keep_sources = true;
  TranslationCostCpu cpu;
  SurfaceQuiltingStats stats;
  Animated a;
  a.quilt = global ? quilt_surface_global(base, swatch, o, cpu, &stats, global_stats)
                   : quilt_surface(base, swatch, o, cpu, &stats);
  a.scale = stats.swatch_scale;
  TetStretchCpu stretch;
  a.rest = embed_quilt(a.quilt, {}, stretch, &a.embedding);
  return a;
}

// The 4 x 4 weave at 8 segments round a thread: small enough for many seams on a small plane.
TriMesh small_weave() {
  WeaveOptions w;
  w.threads_x = w.threads_y = 4;
  w.tube_segments = 8;
  return plain_weave(w);
}

// The largest change of the displacement d (#V by 3) along an edge of F.
double largest_edge_change(const MatrixX3d& d, const MatrixX3i& F) {
  double step = 0;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      step = std::max(step, (d.row(F(f, k)) - d.row(F(f, (k + 1) % 3))).norm());
  return step;
}

// The weave by the local patches, whose threads are cut and stitched at patch seams (section
// 2.7), some of parts of different swatch threads: each swatch thread k lifted by (k + 1) / 50 of
// the layer's thickness. A vertex away from a seam moves by its own thread's lift, along the
// plane's normal (a thread's frames are bent to the base's normal); a stitched thread's parts
// meet without a step: along every edge the motion changes by well under one step (by one or
// more across a seam between two threads, unblended).
TEST(SwatchAnimation, StitchedThreadsBlendTheirPartsMotions) {
  const TriMesh swatch = small_weave();
  const Animated a = quilt_with_sources(test::plane_grid(2, 1.5, 20, 15), swatch, 0.2, false);
  int of_two_threads = 0;
  for (const SurfaceElement& s : a.quilt.elements)
    of_two_threads += std::any_of(s.source_element.begin(), s.source_element.end(),
                                  [&](int e) { return e != s.source_element[0]; });
  ASSERT_GT(of_two_threads, 0);
  SwatchAnimation animation(a.quilt, a.embedding.kept, a.rest, swatch, a.scale);
  // The frame equal to the swatch moves nothing, bit for bit.
  EXPECT_TRUE(animation.frame(swatch_motion(swatch, swatch, a.scale, "f")).V == a.rest.V);
  std::vector<int> fc;
  connected_components(swatch.F, swatch.num_vertices(), fc);
  TriMesh lifted = swatch;
  const double H = swatch.V.col(2).maxCoeff() - swatch.V.col(2).minCoeff();
  for (int f = 0; f < swatch.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      lifted.V(swatch.F(f, k), 2) = swatch.V(swatch.F(f, k), 2) + H * (fc[f] + 1) / 50.0;
  const MatrixX3d d = animation.frame(swatch_motion(swatch, lifted, a.scale, "f")).V - a.rest.V;
  const double unit = H * a.scale / 50;  // one step of lift in the output
  int whole = 0;
  for (int v = 0; v < a.rest.num_vertices(); ++v) {
    const double steps = d.row(v).norm() / unit;
    ASSERT_LT(d.row(v).head<2>().norm(), 1e-3 * d.row(v).norm()) << v;
    ASSERT_GE(steps, 0.99) << v;  // a blend of turned lifts is a little shorter
    whole += std::abs(steps - std::round(steps)) < 1e-6;
  }
  const int blended = a.rest.num_vertices() - whole;
  EXPECT_GT(blended, 0);
  EXPECT_LT(blended, a.rest.num_vertices() / 10);
  const double step = largest_edge_change(d, a.rest.F);
  std::printf(
      "[ measure  ] stitched weave: %d elements of two threads, %d of %d vertices blended; the "
      "motion changes along an edge by at most %.3f lift steps\n",
      of_two_threads, blended, a.rest.num_vertices(), step / unit);
  EXPECT_LT(step, 0.5 * unit);
}

// The weave by the global layout, its threads welded of one-period pieces: a swatch frame that
// lifts every vertex by a tenth of the layer's thickness per swatch unit along x (a ramp, so not
// periodic) would step where two pieces along x are welded, by the ramp over one period (two
// thread spacings); blended, the motion changes along any edge by a fraction of that.
TEST(SwatchAnimation, WeldedThreadPiecesBlendAtTheirWelds) {
  const TriMesh swatch = small_weave();
  GlobalQuiltingStats g;
  const Animated a = quilt_with_sources(test::plane_grid(2, 1.5, 20, 15), swatch, 0.2, true, &g);
  ASSERT_TRUE(g.threads);
  ASSERT_GT(g.thread_welds, 0);
  SwatchAnimation animation(a.quilt, a.embedding.kept, a.rest, swatch, a.scale);
  EXPECT_TRUE(animation.frame(swatch_motion(swatch, swatch, a.scale, "f")).V == a.rest.V);
  TriMesh ramp = swatch;
  const double H = swatch.V.col(2).maxCoeff() - swatch.V.col(2).minCoeff();
  ramp.V.col(2) += 0.1 * H * swatch.V.col(0);
  const MatrixX3d d = animation.frame(swatch_motion(swatch, ramp, a.scale, "f")).V - a.rest.V;
  const double weld_step = 0.1 * H * 2 * WeaveOptions().spacing * a.scale;
  const double step = largest_edge_change(d, a.rest.F);
  std::printf(
      "[ measure  ] welded weave: %d welds; the motion changes along an edge by at most %.3f of "
      "the step at a weld\n",
      g.thread_welds, step / weld_step);
  EXPECT_LT(step, 0.3 * weld_step);
}

// The 6 x 6 weave on a sphere at 0.2, quilted over the global layout's plane (30 threads, each
// round a good part of the sphere), lifted by a fifth of its thickness: every vertex moves along
// the sphere's normal under it and nothing meets, so nothing is damped. With one frame per part
// (before bend_with_surface; the command line on a 48 x 24 sphere) the lifts were up to 62
// degrees off the normal and all 30 threads were damped.
TEST(SwatchAnimation, ThreadsRoundASphereLiftAlongItsNormal) {
  const TriMesh swatch = plain_weave();
  const Animated a = quilt_with_sources(test::uv_sphere(1, 48, 24), swatch, 0.2, true);
  SwatchAnimation animation(a.quilt, a.embedding.kept, a.rest, swatch, a.scale);
  TriMesh lifted = swatch;
  lifted.V.col(2).array() += 0.2 * (swatch.V.col(2).maxCoeff() - swatch.V.col(2).minCoeff());
  const std::vector<SwatchMotion> motions{swatch_motion(swatch, lifted, a.scale, "f")};
  SettledMotionStats settled;
  animation.settle(motions, &settled);
  EXPECT_EQ(settled.damped + settled.stilled, 0);
  const MatrixX3d d = animation.frame(motions[0]).V - a.rest.V;
  double worst = 1;
  for (int v = 0; v < a.rest.num_vertices(); ++v)
    worst = std::min(worst, d.row(v).normalized().dot(a.rest.V.row(v).normalized()));
  std::printf(
      "[ measure  ] weave round a sphere: %zu threads, lifts at least %.4f along the normal\n",
      a.quilt.elements.size(), worst);
  EXPECT_GT(worst, 0.99);
}

TEST(SwatchAnimation, OtherConnectivityAndResultsWithoutSourcesAreRefused) {
  const TriMesh swatch = ivy_swatch();
  TriMesh other = swatch;
  other.F.row(0) = other.F.row(0).reverse().eval();
  EXPECT_THROW(swatch_motion(swatch, other, 1.0, "f"), InvalidInput);
  TriMesh fewer = swatch;
  fewer.V.conservativeResize(fewer.V.rows() - 1, 3);
  EXPECT_THROW(swatch_motion(swatch, fewer, 1.0, "f"), InvalidInput);
  TriMesh nan = swatch;
  nan.V(3, 1) = std::nan("");
  EXPECT_THROW(swatch_motion(swatch, nan, 1.0, "f"), InvalidInput);
  // Chain mail by the local patches and by the global layout's lattice keeps its sources; a result
  // made without keep_sources does not.
  ChainMailOptions mail;
  mail.rows = mail.cols = 4;
  const TriMesh rings = chainmail_4in1(mail);
  SurfaceQuiltingOptions o;
  o.scale = 0.3;
  o.keep_sources = true;
  TranslationCostCpu cpu;
  SurfaceQuiltingStats stats, global_stats;
  const TriMesh plane = test::plane_grid(2, 1.5, 20, 15);
  SurfaceQuilt q = quilt_surface(plane, rings, o, cpu, &stats);
  const SurfaceQuilt g = quilt_surface_global(plane, rings, o, cpu, &global_stats);
  QuiltEmbeddingStats e, ge;
  TetStretchCpu stretch;
  const TriMesh rest = embed_quilt(q, {}, stretch, &e);
  const TriMesh global_rest = embed_quilt(g, {}, stretch, &ge);
  EXPECT_NO_THROW(SwatchAnimation(g, ge.kept, global_rest, rings, global_stats.swatch_scale));
  EXPECT_NO_THROW(SwatchAnimation(q, e.kept, rest, rings, stats.swatch_scale));
  o.keep_sources = false;
  const SurfaceQuilt none = quilt_surface(plane, rings, o, cpu, &stats);
  QuiltEmbeddingStats ne;
  const TriMesh none_rest = embed_quilt(none, {}, stretch, &ne);
  EXPECT_THROW(SwatchAnimation(none, ne.kept, none_rest, rings, stats.swatch_scale), InvalidInput);
}

}  // namespace
}  // namespace mq
