#include "core/surface_coverage.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "core/closest_point_query.h"
#include "core/errors.h"
#include "core/geometry_measures.h"

namespace mq {

double surface_coverage(const TriMesh& base, const TriMesh& output, double radius) {
  MQ_CHECK(base.F.rows() > 0, InvalidInput, "coverage: the base has no faces");
  MQ_CHECK(base.V.allFinite(), InvalidInput, "coverage: the base has non-finite vertices");
  MQ_CHECK(radius >= 0 && std::isfinite(radius), InvalidInput,
           "coverage: radius must be finite and >= 0, got ", radius);
  if (output.F.rows() == 0) return 0.0;
  const ClosestPointQuery query(output.V, output.F);
  const Eigen::VectorXd A = face_areas(base.V, base.F);
  std::vector<unsigned char> covered(static_cast<size_t>(base.F.rows()), 0);
  tbb::parallel_for(Eigen::Index(0), base.F.rows(), [&](Eigen::Index f) {
    const Vector3d c =
        (base.V.row(base.F(f, 0)) + base.V.row(base.F(f, 1)) + base.V.row(base.F(f, 2)))
            .transpose() /
        3.0;
    covered[static_cast<size_t>(f)] = query.closest(c, radius).face >= 0;
  });
  // Summed in face order so the result does not depend on the thread count.
  double sum = 0, total = 0;
  for (Eigen::Index f = 0; f < base.F.rows(); ++f) {
    total += A(f);
    if (covered[static_cast<size_t>(f)]) sum += A(f);
  }
  return total > 0 ? sum / total : 0.0;
}

}  // namespace mq
