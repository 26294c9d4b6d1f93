#include "core/shell/swatch_animation.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <set>

#include "core/common/errors.h"
#include "core/common/union_find.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
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

SurfaceQuilt layer_quilt(const TriMesh& layer, const PlaneSources& sources,
                         const Vector3d& normal) {
  MQ_CHECK(sources.point.rows() == layer.num_vertices() &&
               sources.element.size() == static_cast<size_t>(layer.num_vertices()),
           InternalError, "swatch animation: the layer's sources do not match it");
  SurfaceQuilt quilt;
  // The base: any two triangles with the layer's normal (the frames need only that).
  const Eigen::Matrix3d frame =
      Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), normal).toRotationMatrix();
  quilt.base.V.resize(4, 3);
  quilt.base.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  quilt.base.V = (quilt.base.V * frame.transpose()).eval();
  quilt.base.F.resize(2, 3);
  quilt.base.F << 0, 1, 2, 0, 2, 3;
  quilt.stitched = true;
  Eigen::Index v0 = 0, f0 = 0;
  for (size_t i = 0; i < sources.element_vertices.size(); ++i) {
    const Eigen::Index nv = sources.element_vertices[i], nf = sources.element_faces[i];
    MQ_CHECK(v0 + nv <= layer.num_vertices() && f0 + nf <= layer.num_faces(), InternalError,
             "swatch animation: the layer's elements do not match it");
    SurfaceElement e;
    e.F = layer.F.middleRows(f0, nf).array() - static_cast<int>(v0);
    e.face.assign(static_cast<size_t>(nv), 0);
    e.barycentric = MatrixX3d::Constant(nv, 3, 1.0 / 3);
    e.height = Eigen::VectorXd::Zero(nv);
    e.source = sources.point.middleRows(v0, nv);
    e.source_element.assign(sources.element.begin() + v0, sources.element.begin() + v0 + nv);
    quilt.elements.push_back(std::move(e));
    v0 += nv;
    f0 += nf;
  }
  MQ_CHECK(v0 == layer.num_vertices() && f0 == layer.num_faces(), InternalError,
           "swatch animation: the layer's elements do not match it");
  return quilt;
}

SwatchAnimation::SwatchAnimation(const SurfaceQuilt& quilt, const std::vector<int>& kept,
                                 const TriMesh& rest, const TriMesh& swatch, double scale)
    : rest_(rest), sized_(quilt.sized) {
  const PreparedSwatch prepared = prepared_at(swatch, scale);
  for (const Element& e : prepared.elements) element_faces_.push_back(e.F);
  const MatrixX3d source = gather_sources(quilt, kept, prepared);
  locate_sources(quilt.repeat, prepared, source);
  part_ = element_;
  // Each vertex's frame: on the repeated element (a stem), the points within the shell height of
  // it in the swatch (sources unwrapped) fitted onto theirs in the output; that reach spans the
  // stem's cross-section, which so turns as one. Any other element takes one frame per part
  // (find_parts; a frame per vertex turned a stitched thread's deformed stretches by up to 10
  // degrees on a plane, enough to push it through the threads crossing it), which a long one
  // bends with the surface (bend_with_surface).
  const double reach = prepared.size.z();
  shell_ = reach;
  rotation_.resize(static_cast<size_t>(rest.num_vertices()));
  std::vector<Eigen::Index> first{0};
  for (const int k : kept)
    first.push_back(first.back() +
                    static_cast<Eigen::Index>(quilt.elements[static_cast<size_t>(k)].face.size()));
  if (quilt.stitched) find_parts(quilt, kept, source, first);
  // Long swatch elements: footprints at least 4 times longer than wide.
  std::vector<char> long_element;
  for (const Element& e : prepared.elements) long_element.push_back(e.long_footprint());
  const bool any_long =
      std::find(long_element.begin(), long_element.end(), 1) != long_element.end();
  fade_ = quilt.stitched && any_long;
  const MatrixX3d normals = any_long ? vertex_normals(quilt.base.V, quilt.base.F) : MatrixX3d();
  tbb::parallel_for(size_t{0}, kept.size(), [&](size_t i) {
    const Eigen::Index v0 = first[i], n = first[i + 1] - first[i];
    if (along_[static_cast<size_t>(v0)] >= 0) {
      fit_frames(source, rest.V, v0, n, reach);
      return;
    }
    fit_frame(source, rest.V, v0, n);
    if (long_element[static_cast<size_t>(element_[static_cast<size_t>(v0)])])
      bend_with_surface(quilt.elements[static_cast<size_t>(kept[i])], quilt.base, normals, v0);
  });
  find_seams();
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
    const auto known = [&](int s) {
      return s >= 0 && s < static_cast<int>(prepared.elements.size());
    };
    MQ_CHECK(e.source.rows() == n && e.source_element.size() == static_cast<size_t>(n) &&
                 std::all_of(e.source_element.begin(), e.source_element.end(), known),
             InvalidInput,
             "a swatch animation is followed by the vine method (ivy), the global layout's "
             "lattice (chain mail) and the local patches only: this result's elements do not say "
             "where in the swatch they come from");
    MQ_CHECK(v0 + n <= nv, InternalError,
             "swatch animation: the output is smaller than its elements");
    source.middleRows(v0, n) = e.source;
    std::copy(e.source_element.begin(), e.source_element.end(), element_.begin() + v0);
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
  const auto from = part_.begin() + v0, to = from + n;
  if (std::any_of(from, to, [&](int e) { return e != *from; })) {
    fit_parts(source, out, v0, n);
    return;
  }
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

// A long element (a thread) follows the surface along its course: each vertex's frame is turned
// by the least rotation that takes its swatch normal (the thickness axis, z) to the base's normal
// under the vertex (normals: per vertex of the quilt's base). One frame for a thread's part laid
// round a sphere moved its ends sideways into the threads beside it, and the part's best fit
// rolled with the bend (lifts up to 62 degrees off the normal); on a plane nothing turns.
void SwatchAnimation::bend_with_surface(const SurfaceElement& e, const TriMesh& base,
                                        const MatrixX3d& normals, Eigen::Index v0) {
  for (size_t u = 0; u < e.face.size(); ++u) {
    Vector3d under = Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      under += e.barycentric(static_cast<Eigen::Index>(u), k) *
               normals.row(base.F(e.face[u], k)).transpose();
    Eigen::Matrix3f& R = rotation_[static_cast<size_t>(v0) + u];
    const Vector3d z = R.col(2).cast<double>();
    if (!(under.squaredNorm() > 0) || !(z.squaredNorm() > 0)) continue;
    R = Eigen::Quaterniond::FromTwoVectors(z, under).toRotationMatrix().cast<float>() * R;
  }
}

// Each vertex's part (part_): of an element stitched of parts of several swatch copies
// (SurfaceQuilt::stitched), the vertices joined by edges between two vertices of one swatch
// element whose length there is the element's usual ratio to the output's (within 2x): an edge
// across a seam joins two copies, whose sources lie apart (other elements, or one element's
// points from two places). Numbered by their first vertex.
void SwatchAnimation::find_parts(const SurfaceQuilt& quilt, const std::vector<int>& kept,
                                 const MatrixX3d& source, const std::vector<Eigen::Index>& first) {
  std::vector<Eigen::Index> first_face{0};
  for (const int k : kept)
    first_face.push_back(first_face.back() + quilt.elements[static_cast<size_t>(k)].F.rows());
  MQ_CHECK(first_face.back() == rest_.num_faces(), InternalError,
           "swatch animation: the output's faces are not its elements'");
  tbb::parallel_for(size_t{0}, kept.size(), [&](size_t i) {
    const Eigen::Index v0 = first[i], f0 = first_face[i], f1 = first_face[i + 1];
    const auto ratio = [&](int a, int b) {
      const double out = (rest_.V.row(a) - rest_.V.row(b)).norm();
      return out > 0 ? (source.row(a) - source.row(b)).norm() / out : 0.0;
    };
    std::vector<double> ratios;
    for (Eigen::Index f = f0; f < f1; ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = rest_.F(f, k), b = rest_.F(f, (k + 1) % 3);
        if (element_[static_cast<size_t>(a)] == element_[static_cast<size_t>(b)])
          ratios.push_back(ratio(a, b));
      }
    if (ratios.empty()) return;
    std::nth_element(ratios.begin(),
                     ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
    const double usual = ratios[ratios.size() / 2];
    UnionFind parts(static_cast<int>(first[i + 1] - v0));
    for (Eigen::Index f = f0; f < f1; ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = rest_.F(f, k), b = rest_.F(f, (k + 1) % 3);
        const double r = ratio(a, b);
        if (element_[static_cast<size_t>(a)] == element_[static_cast<size_t>(b)] &&
            r <= 2 * usual && 2 * r >= usual)
          parts.unite(static_cast<int>(a - v0), static_cast<int>(b - v0));
      }
    for (Eigen::Index v = v0; v < first[i + 1]; ++v)
      part_[static_cast<size_t>(v)] = static_cast<int>(v0) + parts.find(static_cast<int>(v - v0));
  });
}

// The frames of the n vertices from v0, an element stitched of parts of several swatch copies
// (the local patches, section 2.7): one per part (find_parts), fitted alone (each part moves as
// its own copy, and the parts' sources lie apart in the swatch).
void SwatchAnimation::fit_parts(const MatrixX3d& source, const MatrixX3d& out, Eigen::Index v0,
                                Eigen::Index n) {
  std::vector<std::pair<int, Eigen::Index>> part;  // (part, vertex), sorted
  for (Eigen::Index v = v0; v < v0 + n; ++v) part.emplace_back(part_[static_cast<size_t>(v)], v);
  std::sort(part.begin(), part.end());
  for (size_t a = 0, b = 0; a < part.size(); a = b) {
    while (b < part.size() && part[b].first == part[a].first) ++b;
    Vector3d p = Vector3d::Zero(), q = Vector3d::Zero();
    for (size_t i = a; i < b; ++i) {
      p += source.row(part[i].second).transpose();
      q += out.row(part[i].second).transpose();
    }
    p /= static_cast<double>(b - a);
    q /= static_cast<double>(b - a);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    double spread_out = 0, spread_source = 0;
    for (size_t i = a; i < b; ++i) {
      const Vector3d s = source.row(part[i].second).transpose() - p,
                     o = out.row(part[i].second).transpose() - q;
      cov += o * s.transpose();
      spread_out += o.squaredNorm(), spread_source += s.squaredNorm();
    }
    const Eigen::Matrix3f R =
        (nearest_rotation(cov) * size_ratio(spread_out, spread_source)).cast<float>();
    for (size_t i = a; i < b; ++i) rotation_[static_cast<size_t>(part[i].second)] = R;
  }
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

// The vertices within kSeamRings edges of a seam, where an element stitched of parts of several
// swatch elements joins two of them (an edge between vertices of different sources), and each
// one's neighbours.
void SwatchAnimation::find_seams() {
  const int nv = rest_.num_vertices();
  const auto differs = [&](int v, int u) {
    return part_[static_cast<size_t>(u)] != part_[static_cast<size_t>(v)];
  };
  std::vector<int> seam;
  for (int f = 0; f < rest_.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      if (differs(rest_.F(f, k), rest_.F(f, (k + 1) % 3))) seam.push_back(rest_.F(f, k));
  if (seam.empty()) return;  // no element of two sources: nothing to blend
  const Adjacency adjacency = vertex_adjacency(rest_.F, nv);
  std::vector<int> ring(static_cast<size_t>(nv), -1);
  for (const int v : seam) ring[static_cast<size_t>(v)] = 0;
  std::vector<int> band;
  for (int v = 0; v < nv; ++v)
    if (ring[static_cast<size_t>(v)] == 0) band.push_back(v);
  for (size_t i = 0; i < band.size(); ++i) {
    const int v = band[i];
    if (ring[static_cast<size_t>(v)] == kSeamRings) continue;
    for (const int* u = adjacency.begin(v); u != adjacency.end(v); ++u)
      if (ring[static_cast<size_t>(*u)] < 0) {
        ring[static_cast<size_t>(*u)] = ring[static_cast<size_t>(v)] + 1;
        band.push_back(*u);
      }
  }
  std::sort(band.begin(), band.end());
  seams_.vertices = band;
  seams_.neighbours.offsets.push_back(0);
  for (const int v : band) {
    seams_.neighbours.indices.insert(seams_.neighbours.indices.end(), adjacency.begin(v),
                                     adjacency.end(v));
    seams_.neighbours.offsets.push_back(static_cast<int>(seams_.neighbours.indices.size()));
  }
}

// The displacements D (#V(rest) by 3) blended across the seams: each seam vertex's taken as the
// mean of its neighbours' (Jacobi steps, the vertices beyond the band held), so that the parts'
// motions meet without a step (issue 25: displacements blend where stitching merged elements).
void SwatchAnimation::blend_seams(MatrixX3d& D) const {
  const std::vector<int>& band = seams_.vertices;
  if (band.empty()) return;
  MatrixX3d next(static_cast<Eigen::Index>(band.size()), 3);
  for (int step = 0; step < kSeamSteps; ++step) {
    tbb::parallel_for(size_t{0}, band.size(), [&](size_t i) {
      const int* from = seams_.neighbours.begin(static_cast<int>(i));
      const int* to = seams_.neighbours.end(static_cast<int>(i));
      Vector3d sum = Vector3d::Zero();
      for (const int* u = from; u != to; ++u) sum += D.row(*u).transpose();
      next.row(static_cast<Eigen::Index>(i)) =
          (from == to ? D.row(band[i]).transpose() : Vector3d(sum / (to - from))).transpose();
    });
    for (size_t i = 0; i < band.size(); ++i)
      D.row(band[i]) = next.row(static_cast<Eigen::Index>(i));
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
  MatrixX3d D = MatrixX3d::Zero(rest_.num_vertices(), 3);
  tbb::parallel_for(0, rest_.num_vertices(), [&](int v) {
    const double a = amplitude[static_cast<size_t>(component_[static_cast<size_t>(v)])] *
                     (fade_share_.empty() ? 1.0 : fade_share_[static_cast<size_t>(v)]);
    if (a == 0) return;
    const Vector3d d = displacement(motion, sections, static_cast<size_t>(v));
    if (d.isZero(0)) return;
    D.row(v) = (a * (rotation_[static_cast<size_t>(v)].cast<double>() * d)).transpose();
  });
  blend_seams(D);
  // A vertex that does not move keeps its rest position bit for bit.
  tbb::parallel_for(0, rest_.num_vertices(), [&](int v) {
    if (!D.row(v).isZero(0)) V.row(v) += D.row(v);
  });
  return V;
}

// Interlaced threads cannot be damped one by one: a thread moving half as much, or not at all,
// meets the threads crossing it as they move, and the damping spread to every thread (the cup's
// weave lifted by 0.2 of its thickness: 7 threads folded in its concave corners, all 59 ended
// still). So where the frames make faces meet, every vertex's motion fades alike, to none at the
// meeting and in full beyond a radius (2, 4, 8 then 16 shell heights, while faces still meet):
// neighbours there keep their places relative to each other.
void SwatchAnimation::fade_near_meetings(const std::vector<SwatchMotion>& motions) {
  const int nv = rest_.num_vertices();
  IntersectionOptions all;
  all.between_components_only = false;
  const auto at_rest = intersecting_face_pairs(rest_.V, rest_.F, all);
  const std::set<std::pair<int, int>> known(at_rest.begin(), at_rest.end());
  std::vector<Vector3d> meetings;  // rest positions of the faces that meet in some frame
  const std::vector<double> whole(amplitude_.size(), 1.0);
  for (int round = 0; round < 4; ++round) {
    const size_t before = meetings.size();
    for (const SwatchMotion& m : motions) {
      const MatrixX3d V = positions(m, whole);
      for (const auto& [f, g] :
           intersecting_face_pairs_touching(V, rest_.F, moved_faces(rest_.V, V, rest_.F))) {
        if (known.count({f, g})) continue;
        for (const int h : {f, g})
          meetings.push_back(
              (rest_.V.row(rest_.F(h, 0)) + rest_.V.row(rest_.F(h, 1)) + rest_.V.row(rest_.F(h, 2)))
                  .transpose() /
              3.0);
      }
    }
    if (meetings.size() == before) break;
    // Each vertex's share: the smoothstep of its distance to the nearest meeting over the
    // radius, found among the meetings in the 27 cells of that size around it.
    const double radius = 2 * shell_ * std::pow(2.0, round);
    using Cell = std::array<std::int64_t, 3>;
    const auto cell_of = [&](const Vector3d& p) {
      return Cell{static_cast<std::int64_t>(std::floor(p.x() / radius)),
                  static_cast<std::int64_t>(std::floor(p.y() / radius)),
                  static_cast<std::int64_t>(std::floor(p.z() / radius))};
    };
    std::map<Cell, std::vector<Vector3d>> cells;
    for (const Vector3d& p : meetings) cells[cell_of(p)].push_back(p);
    fade_share_.assign(static_cast<size_t>(nv), 1.0);
    tbb::parallel_for(0, nv, [&](int v) {
      const Vector3d x = rest_.V.row(v).transpose();
      const Cell c = cell_of(x);
      double nearest = radius;
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dz = -1; dz <= 1; ++dz) {
            const auto it = cells.find(Cell{c[0] + dx, c[1] + dy, c[2] + dz});
            if (it == cells.end()) continue;
            for (const Vector3d& p : it->second) nearest = std::min(nearest, (p - x).norm());
          }
      const double t = nearest / radius;
      fade_share_[static_cast<size_t>(v)] = t * t * (3 - 2 * t);
    });
  }
  std::vector<char> faded(amplitude_.size(), 0);
  for (int v = 0; v < nv && !fade_share_.empty(); ++v)
    if (fade_share_[static_cast<size_t>(v)] < 1) faded[component_[static_cast<size_t>(v)]] = 1;
  faded_elements_ = static_cast<int>(std::count(faded.begin(), faded.end(), 1));
}

void SwatchAnimation::settle(const std::vector<SwatchMotion>& motions, SettledMotionStats* stats) {
  if (fade_) fade_near_meetings(motions);
  amplitude_ = settled_amplitudes(
      rest_.V, rest_.F, static_cast<int>(motions.size()),
      [&](int k, const std::vector<double>& a) {
        return positions(motions[static_cast<size_t>(k)], a);
      },
      stats);
  if (stats) stats->faded = faded_elements_;
}

TriMesh SwatchAnimation::frame(const SwatchMotion& motion) const {
  TriMesh out = rest_;
  out.V = positions(motion, amplitude_);
  return out;
}

}  // namespace mq
