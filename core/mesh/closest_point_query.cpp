#include "core/mesh/closest_point_query.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <utility>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/point_triangle.h"

namespace mq {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Relative slack added to every radius given to Embree (see the class comment).
constexpr double kRelativeSlack = 1e-6;
// Absolute floor of the slack, for meshes collapsed at the origin.
constexpr double kAbsoluteSlack = 1e-30;

// Smallest float >= x (inf when x does not fit), so a float radius never undercuts x.
float float_at_least(double x) {
  if (!(x < static_cast<double>(std::numeric_limits<float>::max())))
    return std::numeric_limits<float>::infinity();
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Per-query state handed to the Embree callback; lives on the querying thread's stack.
struct QueryState {
  const MatrixX3d* V;
  const MatrixX3i* F;
  const MatrixX3d* FN;
  Vector3d p;
  Vector3d n;         // unit query normal (match only)
  bool match;         // rank by Eq. (1) instead of distance
  double lambda;      // Eq. (1) distance weight
  double max_radius;  // inclusive cap on the distance
  double slack;       // enlargement of radii handed to Embree
  ClosestPointHit best;
};

// Called by Embree for every face whose (float) bounds meet the current query sphere.
bool visit_face(RTCPointQueryFunctionArguments* args) {
  QueryState& s = *static_cast<QueryState*>(args->userPtr);
  const int f = static_cast<int>(args->primID);
  const MatrixX3d& V = *s.V;
  const Vector3d a = V.row((*s.F)(f, 0)).transpose(), b = V.row((*s.F)(f, 1)).transpose(),
                 c = V.row((*s.F)(f, 2)).transpose();
  const Vector3d w = closest_point_barycentric<double>(s.p, a, b, c);
  const Vector3d q = w(0) * a + w(1) * b + w(2) * c;
  const double d = (s.p - q).norm();
  if (!(d <= s.max_radius)) return false;
  const double cost =
      s.match ? (1.0 + s.lambda * d) * (1.0 + (s.n - s.FN->row(f).transpose()).norm()) : d;
  // Embree's visiting order is arbitrary (and a face may be visited twice with spatial
  // splits), so the winner is the lexicographic minimum of (cost, face).
  if (!(cost < s.best.cost || (cost == s.best.cost && f < s.best.face))) return false;
  s.best.face = f;
  s.best.point = q;
  s.best.barycentric = w;
  s.best.distance = d;
  s.best.cost = cost;

  // Largest distance at which another face could still tie or win.
  double bound = d;
  if (s.match) {
    // The normal factor is >= 1, so winning needs 1 + lambda*d' <= cost. The extra term
    // covers rounding of (cost - 1) / lambda, which can be large for tiny lambda.
    bound = s.lambda > 0 ? (cost - 1.0) / s.lambda + 1e-12 * cost / s.lambda : kInfinity;
  }
  const float r = float_at_least(std::min(bound, s.max_radius) + s.slack);
  if (r < args->query->radius) {
    args->query->radius = r;  // only ever shrinks, as Embree requires
    return true;
  }
  return false;
}

void check_point(const Vector3d& p, const char* what) {
  MQ_CHECK(p.allFinite(), InvalidInput, what, " has a non-finite coordinate");
}

void check_radius(double max_radius) {
  MQ_CHECK(max_radius >= 0, InvalidInput, "query radius must be >= 0 (got ", max_radius, ")");
}

void check_lambda(double lambda) {
  MQ_CHECK(std::isfinite(lambda) && lambda >= 0, InvalidInput,
           "match distance weight lambda must be finite and >= 0 (got ", lambda, ")");
}

// Unit normal, or InvalidInput for a zero / non-finite normal.
Vector3d unit_normal(const Vector3d& n, const char* what) {
  const double len = n.norm();
  MQ_CHECK(std::isfinite(len) && len > 0, InvalidInput, what, " must be a finite non-zero vector");
  return n / len;
}

}  // namespace

ClosestPointQuery::ClosestPointQuery(const MatrixX3d& V, const MatrixX3i& F)
    : ClosestPointQuery(EmbreeDevice(), V, F) {}

ClosestPointQuery::ClosestPointQuery(const EmbreeDevice& device, const MatrixX3d& V,
                                     const MatrixX3i& F)
    : device_(device), V_(V), F_(F) {
  MQ_CHECK(device_.get(), InvalidInput, "closest point query: empty Embree device");
  MQ_CHECK(F_.rows() > 0, InvalidInput, "closest point query: mesh has no faces");
  const double float_max = static_cast<double>(std::numeric_limits<float>::max());
  for (Eigen::Index i = 0; i < V_.rows(); ++i)
    MQ_CHECK(V_.row(i).allFinite() && V_.row(i).cwiseAbs().maxCoeff() < float_max, InvalidInput,
             "closest point query: vertex ", i, " has a non-finite or out-of-range coordinate");
  for (Eigen::Index f = 0; f < F_.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(F_(f, k) >= 0 && F_(f, k) < V_.rows(), InvalidInput, "closest point query: face ", f,
               " references vertex ", F_(f, k), " outside [0, ", V_.rows(), ")");
  FN_ = mq::face_normals(V_, F_);
  const BoundingBox box = bounding_box(V_, F_);
  scene_scale_ =
      box.extent().norm() + std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff());

  RTCDevice dev = device_.get();
  scene_ = rtcNewScene(dev);
  if (!scene_) {
    device_.check("closest point query: rtcNewScene");
    MQ_THROW(Error, "closest point query: Embree returned no scene");
  }
  // From here on the destructor will not run if we throw: release the scene ourselves.
  try {
    // Most queries are built for one merge step on a few thousand faces: the high-quality
    // (spatial split) build took 20 ms for 16k faces, the medium one 3 ms, and answers are
    // the same (the callback keeps the exact minimum whatever the visiting order).
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    device_.check("closest point query: rtcNewGeometry");
    // Embree-allocated buffers carry the padding Embree's SIMD loads need.
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), V_.rows()));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), F_.rows()));
    if (!vb || !ib) {
      rtcReleaseGeometry(geom);
      device_.check("closest point query: rtcSetNewGeometryBuffer");
      MQ_THROW(Error, "closest point query: Embree returned no geometry buffer");
    }
    for (Eigen::Index i = 0; i < V_.size(); ++i) vb[i] = static_cast<float>(V_.data()[i]);
    for (Eigen::Index i = 0; i < F_.size(); ++i) ib[i] = static_cast<unsigned>(F_.data()[i]);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);  // the scene holds the reference now
    rtcCommitScene(scene_);
    device_.check("closest point query: building the Embree BVH");
  } catch (...) {
    rtcReleaseScene(scene_);
    throw;
  }
}

ClosestPointQuery::~ClosestPointQuery() {
  if (scene_) rtcReleaseScene(scene_);
}

ClosestPointQuery::ClosestPointQuery(ClosestPointQuery&& other) noexcept
    : device_(std::move(other.device_)),
      scene_(std::exchange(other.scene_, nullptr)),
      V_(std::move(other.V_)),
      F_(std::move(other.F_)),
      FN_(std::move(other.FN_)),
      scene_scale_(other.scene_scale_) {}

ClosestPointQuery& ClosestPointQuery::operator=(ClosestPointQuery&& other) noexcept {
  if (this != &other) {
    if (scene_) rtcReleaseScene(scene_);
    scene_ = std::exchange(other.scene_, nullptr);
    device_ = std::move(other.device_);
    V_ = std::move(other.V_);
    F_ = std::move(other.F_);
    FN_ = std::move(other.FN_);
    scene_scale_ = other.scene_scale_;
  }
  return *this;
}

ClosestPointHit ClosestPointQuery::query(const Vector3d& p, const Vector3d* unit_n, double lambda,
                                         double max_radius) const {
  MQ_ASSERT(scene_ != nullptr);  // used after move
  QueryState s;
  s.V = &V_;
  s.F = &F_;
  s.FN = &FN_;
  s.p = p;
  s.n = unit_n ? *unit_n : Vector3d::Zero();
  s.match = unit_n != nullptr;
  s.lambda = lambda;
  s.max_radius = max_radius;
  s.slack = kRelativeSlack * (scene_scale_ + p.cwiseAbs().maxCoeff()) + kAbsoluteSlack;

  RTCPointQuery q;
  q.x = static_cast<float>(p.x());
  q.y = static_cast<float>(p.y());
  q.z = static_cast<float>(p.z());
  q.time = 0.0f;
  q.radius = float_at_least(max_radius + s.slack);
  // No instancing: an empty instance stack is all the context needs.
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(scene_, &q, &context, visit_face, &s);
  return s.best;
}

ClosestPointHit ClosestPointQuery::closest(const Vector3d& p, double max_radius) const {
  check_point(p, "query point");
  check_radius(max_radius);
  return query(p, nullptr, 0.0, max_radius);
}

ClosestPointHit ClosestPointQuery::match(const Vector3d& p, const Vector3d& n, double lambda,
                                         double max_radius) const {
  check_point(p, "query point");
  check_radius(max_radius);
  check_lambda(lambda);
  const Vector3d unit_n = unit_normal(n, "query normal");
  return query(p, &unit_n, lambda, max_radius);
}

std::vector<ClosestPointHit> ClosestPointQuery::closest(const MatrixX3d& P,
                                                        double max_radius) const {
  check_radius(max_radius);
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    MQ_CHECK(P.row(i).allFinite(), InvalidInput, "query point ", i, " has a non-finite coordinate");
  std::vector<ClosestPointHit> hits(P.rows());
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, P.rows(), 64),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index i = range.begin(); i != range.end(); ++i)
                        hits[i] = query(P.row(i).transpose(), nullptr, 0.0, max_radius);
                    });
  return hits;
}

std::vector<ClosestPointHit> ClosestPointQuery::match(const MatrixX3d& P, const MatrixX3d& NP,
                                                      double lambda, double max_radius) const {
  check_radius(max_radius);
  check_lambda(lambda);
  MQ_CHECK(NP.rows() == P.rows(), InvalidInput, "match: ", P.rows(), " query points but ",
           NP.rows(), " normals");
  MatrixX3d unit_NP(NP.rows(), 3);
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    MQ_CHECK(P.row(i).allFinite(), InvalidInput, "query point ", i, " has a non-finite coordinate");
    // Same arithmetic as unit_normal() so batched and single results agree bit for bit.
    const Vector3d n = NP.row(i).transpose();
    const double len = n.norm();
    MQ_CHECK(std::isfinite(len) && len > 0, InvalidInput, "query normal ", i,
             " must be a finite non-zero vector");
    unit_NP.row(i) = (n / len).transpose();
  }
  std::vector<ClosestPointHit> hits(P.rows());
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, P.rows(), 64),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
                        const Vector3d n = unit_NP.row(i).transpose();
                        hits[i] = query(P.row(i).transpose(), &n, lambda, max_radius);
                      }
                    });
  return hits;
}

Eigen::VectorXd point_mesh_distance(const MatrixX3d& P, const MatrixX3d& V, const MatrixX3i& F) {
  const ClosestPointQuery tree(V, F);
  const std::vector<ClosestPointHit> hits = tree.closest(P);
  Eigen::VectorXd D(P.rows());
  for (Eigen::Index i = 0; i < P.rows(); ++i) D(i) = hits[i].distance;
  return D;
}

}  // namespace mq
