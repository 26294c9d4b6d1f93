#include "core/shell/placement_check.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/errors.h"

namespace mq {

std::vector<ElementHeights> check_element_heights(const SignedHeight& base, const MatrixX3d& V,
                                                  const std::vector<Eigen::Index>& first,
                                                  const PlacementCheckOptions& options,
                                                  const std::vector<char>& check) {
  MQ_CHECK(std::isfinite(options.height) && options.height > 0, InvalidInput,
           "placement check: height must be finite and > 0, got ", options.height);
  MQ_CHECK(std::isfinite(options.tolerance) && options.tolerance >= 0, InvalidInput,
           "placement check: tolerance must be finite and >= 0, got ", options.tolerance);
  MQ_CHECK(!first.empty() && first.front() == 0 && first.back() == V.rows() &&
               std::is_sorted(first.begin(), first.end()),
           InvalidInput, "placement check: element offsets do not cover the ", V.rows(),
           " vertices");
  const size_t ne = first.size() - 1;
  MQ_CHECK(check.empty() || check.size() == ne, InvalidInput, "placement check: ", check.size(),
           " flags for ", ne, " elements");
  MQ_CHECK(V.allFinite(), InvalidInput, "placement check: non-finite vertices");
  const double below = -options.tolerance * options.height;
  const double above = (1 + options.tolerance) * options.height;
  std::vector<ElementHeights> out(ne);
  tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
    if (!check.empty() && !check[k]) return;
    ElementHeights& e = out[k];
    e.lowest = std::numeric_limits<double>::infinity();
    Vector3d anchor = Vector3d::Zero();
    double anchor_height = 0;  // > 0 once an anchor above the base is known
    for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) {
      const Vector3d x = V.row(v).transpose();
      ++e.vertices;
      if (anchor_height > 0) {
        const double r = (x - anchor).norm();
        if (r < anchor_height && anchor_height + r <= above) continue;
      }
      const double h = base(x);
      ++e.queries;
      if (h < e.lowest) {
        e.lowest = h;
        e.lowest_vertex = v;
      }
      e.below += h < below;
      e.above += h > above;
      // Only a point above the base certifies its neighbours: below it, every vertex is measured
      // (so `lowest` is exact).
      anchor = x;
      anchor_height = h;
    }
  });
  return out;
}

std::vector<ElementHeights> lift_out_of_base(const SignedHeight& base, MatrixX3d& V,
                                             const std::vector<Eigen::Index>& first,
                                             const PlacementCheckOptions& options,
                                             const std::vector<char>& lift, int steps,
                                             std::vector<char>* moved) {
  MQ_CHECK(steps >= 1, InvalidInput, "lift out of base: steps must be >= 1, got ", steps);
  const size_t ne = first.empty() ? 0 : first.size() - 1;
  MQ_CHECK(lift.size() == ne, InvalidInput, "lift out of base: ", lift.size(), " flags for ", ne,
           " elements");
  if (moved) moved->assign(ne, 0);
  std::vector<char> todo = lift;
  std::vector<ElementHeights> out(ne);
  for (int step = 0;; ++step) {
    const std::vector<ElementHeights> h = check_element_heights(base, V, first, options, todo);
    for (size_t k = 0; k < ne; ++k)
      if (todo[k]) out[k] = h[k];
    if (step == steps) break;
    bool any = false;
    for (size_t k = 0; k < ne; ++k) {
      todo[k] = todo[k] && h[k].below > 0;
      any = any || todo[k];
    }
    if (!any) break;
    tbb::parallel_for(size_t{0}, ne, [&](size_t k) {
      if (!todo[k]) return;
      const Vector3d x = V.row(h[k].lowest_vertex).transpose();
      ClosestPointHit hit;
      base(x, &hit);
      const Vector3d up = hit.point - x;
      const double depth = up.norm();
      if (!(depth > 0)) return;
      const Vector3d shift = up * (1 + 0.5 * options.tolerance * options.height / depth);
      for (Eigen::Index v = first[k]; v < first[k + 1]; ++v) V.row(v) += shift.transpose();
      if (moved) (*moved)[k] = 1;
    });
  }
  return out;
}

PlacementFigures placement_figures(const std::vector<ElementHeights>& heights,
                                   const std::vector<char>& keep) {
  PlacementFigures f;
  for (size_t k = 0; k < heights.size(); ++k) {
    if (k < keep.size() && !keep[k]) continue;
    f.vertices += heights[k].vertices;
    f.below += heights[k].below;
    f.above += heights[k].above;
    if (heights[k].vertices > 0) f.lowest = std::min(f.lowest, heights[k].lowest);
  }
  return f;
}

}  // namespace mq
