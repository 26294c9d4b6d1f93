#include "core/shell/swatch_animation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/similarity_fit.h"
#include "core/planar/quilt_elements.h"

namespace mq {

namespace {

PreparedSwatch prepared_at(const TriMesh& swatch, double scale) {
  TriMesh scaled = swatch;
  scaled.V *= scale;
  return prepare_swatch(scaled);
}

// The smoothstep weight of the periodic correction at t in [0, 1): 0 where a repeat starts, 1
// where it ends, with zero slope at both.
double seam_weight(double t) { return t * t * (3 - 2 * t); }

}  // namespace

void check_swatch_frame(const TriMesh& swatch, const TriMesh& frame, const std::string& name) {
  MQ_CHECK(frame.num_vertices() == swatch.num_vertices() && frame.F == swatch.F, InvalidInput, name,
           ": the swatch frame has ", frame.num_vertices(), " vertices and ", frame.num_faces(),
           " faces, not the swatch's ", swatch.num_vertices(), " and ", swatch.num_faces(),
           " faces in the same order (frames move the swatch's vertices only)");
  MQ_CHECK(frame.V.allFinite(), InvalidInput, name, ": non-finite vertex coordinates");
}

SwatchMotion swatch_motion(const TriMesh& swatch, const TriMesh& frame, double scale,
                           const std::string& name) {
  check_swatch_frame(swatch, frame, name);
  // The motion in the swatch's own axes, exactly zero where a vertex did not move (a frame equal
  // to the swatch moves nothing, bit for bit: frame 0 of a sequence is the static output), taken
  // into the synthesis frame's axes (prepare_swatch's rotation, an axis permutation: exact) and
  // split into elements as prepare_swatch splits the swatch (by connectivity, which the frame
  // shares). Not the difference of the two prepared swatches: each is translated by its own
  // bounding box, so a frame that moves every vertex alike (a layer lifted) would move none.
  const Eigen::Matrix3d rotation = prepared_at(swatch, scale).rotation;
  TriMesh motion = swatch;
  motion.V = ((frame.V - swatch.V) * scale * rotation.transpose()).eval();
  remove_unreferenced_vertices(motion);
  std::vector<int> fc;
  const int n = connected_components(motion.F, motion.num_vertices(), fc);
  SwatchMotion out;
  for (const std::vector<int>& faces : component_faces(fc, n))
    out.displacement.push_back(extract_faces(motion, faces).V);
  return out;
}

SwatchAnimation::SwatchAnimation(const SurfaceQuilt& quilt, const std::vector<int>& kept,
                                 const TriMesh& rest, const TriMesh& swatch, double scale)
    : rest_(rest), sized_(quilt.sized) {
  const PreparedSwatch prepared = prepared_at(swatch, scale);
  for (const Element& e : prepared.elements) element_faces_.push_back(e.F);
  const MatrixX3d source = gather_sources(quilt, kept, prepared);
  locate_sources(quilt.repeat, prepared, source);
  // Each vertex's frame: on the repeated element (a stem), the points within the shell height of
  // it in the swatch (sources unwrapped) fitted onto theirs in the output; that reach spans the
  // stem's cross-section, which so turns as one. A compact element takes one frame.
  const double reach = prepared.size.z();
  rotation_.resize(static_cast<size_t>(rest.num_vertices()));
  std::vector<Eigen::Index> first{0};
  for (const int k : kept)
    first.push_back(first.back() +
                    static_cast<Eigen::Index>(quilt.elements[static_cast<size_t>(k)].face.size()));
  tbb::parallel_for(size_t{0}, kept.size(), [&](size_t i) {
    const Eigen::Index v0 = first[i], n = first[i + 1] - first[i];
    if (along_[static_cast<size_t>(v0)] >= 0)
      fit_frames(source, rest.V, v0, n, reach);
    else
      fit_frame(source, rest.V, v0, n);
  });
  std::vector<int> face_component;
  const int nv = rest.num_vertices();
  amplitude_.assign(static_cast<size_t>(connected_components(rest.F, nv, face_component)), 1.0);
  component_.assign(static_cast<size_t>(nv), 0);
  for (int f = 0; f < rest.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      component_[static_cast<size_t>(rest.F(f, k))] = face_component[static_cast<size_t>(f)];
}

// The kept elements' sources, in the output's vertex order (#V(rest) by 3), and each vertex's
// swatch element.
MatrixX3d SwatchAnimation::gather_sources(const SurfaceQuilt& quilt, const std::vector<int>& kept,
                                          const PreparedSwatch& prepared) {
  const int nv = rest_.num_vertices();
  element_.assign(static_cast<size_t>(nv), -1);
  MatrixX3d source(nv, 3);
  Eigen::Index v0 = 0;
  for (const int k : kept) {
    const SurfaceElement& e = quilt.elements[static_cast<size_t>(k)];
    const Eigen::Index n = static_cast<Eigen::Index>(e.face.size());
    MQ_CHECK(e.source.rows() == n && e.source_element >= 0 &&
                 e.source_element < static_cast<int>(prepared.elements.size()),
             InvalidInput,
             "a swatch animation is followed by the vine method (ivy) and the global layout's "
             "lattice (chain mail) only: this result's elements do not say where in the swatch "
             "they come from");
    MQ_CHECK(v0 + n <= nv, InternalError,
             "swatch animation: the output is smaller than its elements");
    source.middleRows(v0, n) = e.source;
    for (Eigen::Index i = 0; i < n; ++i) element_[static_cast<size_t>(v0 + i)] = e.source_element;
    v0 += n;
  }
  MQ_CHECK(v0 == nv, InternalError, "swatch animation: the output is larger than its elements");
  return source;
}

// Where each source lies in the swatch: a vertex of a compact element on its element (its face
// and barycentric coordinates); a vertex of the repeated element by its place along one repeat,
// where it takes the motion of the swatch vine's cross-section there (the vine sways, and the
// stems' tubes, swept along their own course, have no vertex of the swatch's to follow).
void SwatchAnimation::locate_sources(const SwatchRepeat& repeat, const PreparedSwatch& prepared,
                                     const MatrixX3d& source) {
  const int nv = rest_.num_vertices();
  location_.resize(static_cast<size_t>(nv));
  along_.assign(static_cast<size_t>(nv), -1.0);
  if (repeat.element >= 0 && repeat.period > 0) {
    repeat_ = repeat;
    const Element& vine = prepared.elements[static_cast<size_t>(repeat.element)];
    // Cross-sections about two mean edges apart: each holds a ring of the vine's vertices.
    repeat_bins_ = std::clamp(
        static_cast<int>(std::lround(repeat.period / (2 * mean_edge_length(vine.V, vine.F)))), 1,
        4096);
    for (Eigen::Index i = 0; i < vine.V.rows(); ++i)
      repeat_bin_.push_back(std::clamp(
          static_cast<int>(std::floor((vine.V.row(i).transpose() - repeat.start).dot(repeat.axis) /
                                      repeat.period * repeat_bins_)),
          0, repeat_bins_ - 1));
  }
  std::vector<std::unique_ptr<ClosestPointQuery>> queries(prepared.elements.size());
  for (size_t e = 0; e < prepared.elements.size(); ++e)
    if (static_cast<int>(e) != repeat_.element)
      queries[e] =
          std::make_unique<ClosestPointQuery>(prepared.elements[e].V, prepared.elements[e].F);
  for (int v = 0; v < nv; ++v) {
    const int e = element_[static_cast<size_t>(v)];
    const Vector3d p = source.row(v).transpose();
    if (e == repeat_.element) {
      const double a = (p - repeat_.start).dot(repeat_.axis) / repeat_.period;
      along_[static_cast<size_t>(v)] = a - std::floor(a);
      continue;
    }
    const ClosestPointHit hit = queries[static_cast<size_t>(e)]->closest(p);
    location_[static_cast<size_t>(v)] = {hit.face, hit.barycentric};
  }
}

// One frame for the n vertices from v0 (a compact element: a leaf): its whole shape in the swatch
// fitted onto the output's. It moves as one, rigidly turned, also where the surface bent it (over a
// wall's edge its two halves would part, or close through each other, with a frame each).
void SwatchAnimation::fit_frame(const MatrixX3d& source, const MatrixX3d& out, Eigen::Index v0,
                                Eigen::Index n) {
  const Vector3d p = source.middleRows(v0, n).colwise().mean().transpose();
  const Vector3d q = out.middleRows(v0, n).colwise().mean().transpose();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double spread_out = 0, spread_source = 0;
  for (Eigen::Index v = v0; v < v0 + n; ++v) {
    const Vector3d a = source.row(v).transpose() - p, b = out.row(v).transpose() - q;
    cov += b * a.transpose();
    spread_out += b.squaredNorm(), spread_source += a.squaredNorm();
  }
  const Eigen::Matrix3f R =
      (nearest_rotation(cov) * size_ratio(spread_out, spread_source)).cast<float>();
  for (Eigen::Index v = v0; v < v0 + n; ++v) rotation_[static_cast<size_t>(v)] = R;
}

// The frames of the n vertices from v0 (one element): for each, the rotation that best fits its
// neighbours within `reach` in the swatch (source) onto the same in the output (out).
void SwatchAnimation::fit_frames(const MatrixX3d& source, const MatrixX3d& out, Eigen::Index v0,
                                 Eigen::Index n, double reach) {
  // The element's sources in cells of side `reach`, sorted by cell.
  using Cell = std::array<std::int64_t, 3>;
  const auto cell_of = [&](Eigen::Index v) {
    return Cell{static_cast<std::int64_t>(std::floor(source(v, 0) / reach)),
                static_cast<std::int64_t>(std::floor(source(v, 1) / reach)),
                static_cast<std::int64_t>(std::floor(source(v, 2) / reach))};
  };
  std::vector<std::pair<Cell, Eigen::Index>> cells;
  cells.reserve(static_cast<size_t>(n));
  for (Eigen::Index v = v0; v < v0 + n; ++v) cells.emplace_back(cell_of(v), v);
  std::sort(cells.begin(), cells.end());
  const double r2 = reach * reach;
  for (Eigen::Index v = v0; v < v0 + n; ++v) {
    const Vector3d p = source.row(v).transpose(), q = out.row(v).transpose();
    const Cell c = cell_of(v);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    double spread_out = 0, spread_source = 0;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const Cell k{c[0] + dx, c[1] + dy, c[2] + dz};
          auto it =
              std::lower_bound(cells.begin(), cells.end(), std::make_pair(k, Eigen::Index{0}));
          for (; it != cells.end() && it->first == k; ++it) {
            const Vector3d a = source.row(it->second).transpose() - p;
            const double d2 = a.squaredNorm();
            if (d2 >= r2) continue;
            // Nearer points weigh more, fading to none at the reach.
            const double w = (1 - d2 / r2) * (1 - d2 / r2);
            const Vector3d b = out.row(it->second).transpose() - q;
            cov += w * b * a.transpose();
            spread_out += w * b.squaredNorm(), spread_source += w * d2;
          }
        }
    rotation_[static_cast<size_t>(v)] =
        (nearest_rotation(cov) * size_ratio(spread_out, spread_source)).cast<float>();
  }
}

// The repeated element's motion per cross-section (repeat_bins_ by 3): the mean displacement of
// the swatch vine's vertices in each, an empty one taken between its nearest filled neighbours.
MatrixX3d SwatchAnimation::cross_sections(const SwatchMotion& motion) const {
  MatrixX3d sum = MatrixX3d::Zero(repeat_bins_, 3);
  if (repeat_bins_ == 0) return sum;
  std::vector<int> count(static_cast<size_t>(repeat_bins_), 0);
  const MatrixX3d& d = motion.displacement[static_cast<size_t>(repeat_.element)];
  for (size_t i = 0; i < repeat_bin_.size(); ++i) {
    sum.row(repeat_bin_[i]) += d.row(static_cast<Eigen::Index>(i));
    ++count[static_cast<size_t>(repeat_bin_[i])];
  }
  std::vector<int> filled;
  for (int b = 0; b < repeat_bins_; ++b)
    if (count[static_cast<size_t>(b)] > 0) {
      sum.row(b) /= count[static_cast<size_t>(b)];
      filled.push_back(b);
    }
  if (filled.empty()) return sum;
  for (int b = 0; b < repeat_bins_; ++b) {
    if (count[static_cast<size_t>(b)] > 0) continue;
    const auto hi = std::lower_bound(filled.begin(), filled.end(), b);
    const int r = hi == filled.end() ? filled.back() : *hi;
    const int l = hi == filled.begin() ? filled.front() : *(hi - 1);
    const double t = r == l ? 0 : static_cast<double>(b - l) / (r - l);
    sum.row(b) = (1 - t) * sum.row(l) + t * sum.row(r);
  }
  return sum;
}

Vector3d SwatchAnimation::displacement(const SwatchMotion& motion, const MatrixX3d& sections,
                                       size_t v) const {
  const double a = along_[v];
  if (a < 0) {
    const int e = element_[v];
    const Location& l = location_[v];
    const MatrixX3d& d = motion.displacement[static_cast<size_t>(e)];
    const MatrixX3i& F = element_faces_[static_cast<size_t>(e)];
    Vector3d out = Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (l.barycentric(k) != 0) out += l.barycentric(k) * d.row(F(l.face, k)).transpose();
    return out;
  }
  // Between the cross-sections' centres, and where repeats meet corrected by the difference of
  // the first and last so that the motion is continuous from one repeat to the next.
  const int n = repeat_bins_;
  const double x = std::clamp(a * n - 0.5, 0.0, n - 1.0);
  const int i = std::min(n - 1, static_cast<int>(x));
  const double t = x - i;
  Vector3d d = (1 - t) * sections.row(i).transpose();
  if (t != 0) d += t * sections.row(std::min(n - 1, i + 1)).transpose();
  const double w = seam_weight(a);
  if (w != 0) d += w * (sections.row(0) - sections.row(n - 1)).transpose();
  return d;
}

MatrixX3d SwatchAnimation::positions(const SwatchMotion& motion,
                                     const std::vector<double>& amplitude) const {
  MQ_CHECK(motion.displacement.size() == element_faces_.size(), InternalError,
           "swatch animation: a motion of ", motion.displacement.size(),
           " elements for a swatch of ", element_faces_.size());
  MatrixX3d V = rest_.V;
  const MatrixX3d sections = cross_sections(motion);
  tbb::parallel_for(0, rest_.num_vertices(), [&](int v) {
    const double a = amplitude[static_cast<size_t>(component_[static_cast<size_t>(v)])];
    if (a == 0) return;
    const Vector3d d = displacement(motion, sections, static_cast<size_t>(v));
    if (d.isZero(0)) return;
    V.row(v) += (a * (rotation_[static_cast<size_t>(v)].cast<double>() * d)).transpose();
  });
  return V;
}

void SwatchAnimation::settle(const std::vector<SwatchMotion>& motions, SettledMotionStats* stats) {
  amplitude_ = settled_amplitudes(
      rest_.V, rest_.F, static_cast<int>(motions.size()),
      [&](int k, const std::vector<double>& a) {
        return positions(motions[static_cast<size_t>(k)], a);
      },
      stats);
}

TriMesh SwatchAnimation::frame(const SwatchMotion& motion) const {
  TriMesh out = rest_;
  out.V = positions(motion, amplitude_);
  return out;
}

}  // namespace mq
