// Property checks of a surface quilting result, shared by the fast tests (tests/core) and the
// realistic-size runs (tests/slow).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <set>
#include <utility>
#include <vector>

#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/translation_cost.h"
#include "core/shell/quilt_embedding.h"
#include "core/shell/surface_coverage.h"
#include "core/shell/tet_stretch.h"
#include "core/surface/surface_quilting.h"
#include "tests/core/planar_checks.h"

namespace mq::test {

struct SurfaceRun {
  SurfaceQuilt quilt;
  SurfaceQuiltingStats stats;
  QuiltEmbeddingStats embedding_stats;
  TriMesh output;
};

// The quilt of `swatch` over `base` by `options`, embedded with or without the shell map.
inline SurfaceRun run_surface(const TriMesh& base, const TriMesh& swatch,
                              const SurfaceQuiltingOptions& options, bool shell_map = true) {
  SurfaceRun run;
  TranslationCostCpu cost;
  run.quilt = quilt_surface(base, swatch, options, cost, &run.stats);
  QuiltEmbeddingOptions embedding;
  embedding.shell_map = shell_map;
  TetStretchCpu stretch;
  run.output = embed_quilt(run.quilt, embedding, stretch, &run.embedding_stats);
  return run;
}

inline SurfaceRun run_surface(const TriMesh& base, const TriMesh& swatch, double scale,
                              bool shell_map = true, const MatrixX3d& field = MatrixX3d()) {
  SurfaceQuiltingOptions options;
  options.scale = scale;
  options.field = field;
  return run_surface(base, swatch, options, shell_map);
}

// What intersects when `quilt` is embedded with the given options but without removing
// intersecting elements (how much the embedding itself creates): face pairs of different
// elements, and the distinct pairs of elements (connected components) they belong to.
struct Intersections {
  size_t faces = 0, elements = 0;
};
inline Intersections intersections_when_embedded(const SurfaceQuilt& quilt, bool shell_map,
                                                 bool optimize_stretch = true,
                                                 QuiltEmbeddingStats* stats = nullptr) {
  QuiltEmbeddingOptions options;
  options.shell_map = shell_map;
  options.optimize_stretch = optimize_stretch;
  options.remove_intersecting = false;
  TetStretchCpu stretch;
  const TriMesh out = embed_quilt(quilt, options, stretch, stats);
  const std::vector<std::pair<int, int>> faces = intersecting_face_pairs(out.V, out.F);
  std::vector<int> element;
  connected_components(out.F, out.num_vertices(), element);
  std::set<std::pair<int, int>> pairs;
  for (const auto& [f, g] : faces)
    pairs.emplace(std::min(element[f], element[g]), std::max(element[f], element[g]));
  return {faces.size(), pairs.size()};
}
inline size_t intersecting_pairs_when_embedded(const SurfaceQuilt& quilt, bool shell_map,
                                               bool optimize_stretch = true,
                                               QuiltEmbeddingStats* stats = nullptr) {
  return intersections_when_embedded(quilt, shell_map, optimize_stretch, stats).faces;
}

// Mean face count and mean surface area of the elements (connected components) of a mesh.
struct ElementSizes {
  int elements = 0;
  double mean_faces = 0, mean_area = 0;
  int max_faces = 0;
};
inline ElementSizes element_sizes(const TriMesh& m) {
  ElementSizes s;
  for (const TriMesh& part : components(m)) {
    ++s.elements;
    s.mean_faces += part.num_faces();
    s.mean_area += face_areas(part.V, part.F).sum();
    s.max_faces = std::max(s.max_faces, part.num_faces());
  }
  if (s.elements > 0) {
    s.mean_faces /= s.elements;
    s.mean_area /= s.elements;
  }
  return s;
}

// The properties issue 4 asks of every surface result.
inline void expect_valid_surface_quilt(const TriMesh& base, const SurfaceRun& run,
                                       double min_coverage) {
  const TriMesh& out = run.output;
  ASSERT_GT(out.num_faces(), 0);
  // Every element closed and manifold.
  int bad = 0;
  for (const TriMesh& part : components(out)) {
    const TopologyReport r = topology_report(part);
    bad += !(r.closed() && r.manifold());
  }
  EXPECT_EQ(bad, 0) << "elements not closed or not manifold";
  // No two elements intersect.
  EXPECT_EQ(intersecting_face_pairs(out.V, out.F).size(), 0u);
  // Every output vertex within the shell: no farther from the base than the shell height.
  const double H = run.quilt.shell_height;
  const Eigen::VectorXd d = point_mesh_distance(out.V, run.quilt.base.V, run.quilt.base.F);
  EXPECT_LE(d.maxCoeff(), 1.05 * H + 1e-9) << "a vertex leaves the shell";
  // Coverage: base points with output geometry within 1.5 shell heights.
  EXPECT_GE(surface_coverage(base, out, 1.5 * H), min_coverage);
  EXPECT_GT(run.embedding_stats.element_area_mean, 0);
}

}  // namespace mq::test
