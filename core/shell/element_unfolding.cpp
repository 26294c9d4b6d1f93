#include "core/shell/element_unfolding.h"

#include <utility>
#include <vector>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/similarity_fit.h"

namespace mq {

MatrixX3d unfold_element(const MatrixX3d& placed, const MatrixX3d& flat, const MatrixX3i& F,
                         const SignedHeight* ground, const PlacementCheckOptions& check) {
  const MatrixX3d rigid = similarity_fit(flat, placed);
  MatrixX3d best = rigid;
  bool found = false;
  const std::vector<Eigen::Index> whole = {0, placed.rows()};
  for (const double keep : {0.95, 0.9, 0.75, 0.5, 0.25, 0.0}) {
    MatrixX3d blend = keep * placed + (1 - keep) * rigid;
    if (keep > 0 && !self_intersecting_components(blend, F).empty()) continue;
    if (!found) {
      best = blend;
      found = true;
    }
    if (!ground || check_element_heights(*ground, blend, whole, check)[0].below == 0) {
      best = std::move(blend);
      break;
    }
  }
  return best;
}

}  // namespace mq
