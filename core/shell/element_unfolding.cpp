#include "core/shell/element_unfolding.h"

#include <utility>
#include <vector>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/similarity_fit.h"

namespace mq {

bool blend_towards_flat(const MatrixX3d& placed, const MatrixX3d& flat,
                        const std::vector<double>& keep,
                        const std::function<bool(MatrixX3d& blend, double keep)>& accept) {
  const MatrixX3d rigid = similarity_fit(flat, placed);
  for (const double k : keep) {
    MatrixX3d blend = k * placed + (1 - k) * rigid;
    if (accept(blend, k)) return true;
  }
  return false;
}

MatrixX3d unfold_element(const MatrixX3d& placed, const MatrixX3d& flat, const MatrixX3i& F,
                         const SignedHeight* ground, const PlacementCheckOptions& check,
                         std::pair<int, int> fold) {
  const std::vector<Eigen::Index> whole = {0, placed.rows()};
  MatrixX3d best, first;
  bool any = false;
  const bool out_of_base = blend_towards_flat(
      placed, flat, {0.95, 0.9, 0.75, 0.5, 0.25, 0.0}, [&](MatrixX3d& blend, double keep) {
        // The fitted flat shape (keep 0) is whole by construction.
        if (keep > 0 && self_intersects(blend, F, &fold)) return false;
        if (!any) {
          first = blend;
          any = true;
        }
        if (ground && check_element_heights(*ground, blend, whole, check)[0].below != 0)
          return false;
        best = std::move(blend);
        return true;
      });
  return out_of_base ? best : first;
}

}  // namespace mq
