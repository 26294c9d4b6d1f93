#include "core/planar/swatch_generators.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_topology.h"
#include "core/mesh/settled_motion.h"

namespace mq {
namespace {

// Uniform in [0, 1) from the top 53 bits of the raw engine output (portable, unlike
// std::uniform_real_distribution).
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
double uniform(std::mt19937_64& rng, double a, double b) { return a + (b - a) * uniform01(rng); }

// Closed tube of the given radius around the polyline C (tangents T), m vertices per cross
// section. The cross-section frame is side = normalize(ref x T), up = T x side, so side x up = T
// and the quads below face outward. loop: the last section joins the first; otherwise both
// ends get a flat fan cap.
TriMesh tube_mesh(const std::vector<Vector3d>& C, const std::vector<Vector3d>& T,
                  const Vector3d& ref, double radius, int m, bool loop) {
  const int n = static_cast<int>(C.size());
  TriMesh t;
  t.V.resize(n * m + (loop ? 0 : 2), 3);
  for (int k = 0; k < n; ++k) {
    const Vector3d tan = T[k].normalized();
    const Vector3d side = ref.cross(tan).normalized();
    const Vector3d up = tan.cross(side);
    for (int j = 0; j < m; ++j) {
      const double phi = 2 * M_PI * j / m;
      t.V.row(k * m + j) = C[k] + radius * (std::cos(phi) * side + std::sin(phi) * up);
    }
  }
  const int segs = loop ? n : n - 1;
  t.F.resize(2 * segs * m + (loop ? 0 : 2 * m), 3);
  int f = 0;
  for (int k = 0; k < segs; ++k) {
    const int k1 = (k + 1) % n;
    for (int j = 0; j < m; ++j) {
      const int j1 = (j + 1) % m;
      const int a = k * m + j, b = k * m + j1, c = k1 * m + j1, d = k1 * m + j;
      t.F.row(f++) << a, b, c;
      t.F.row(f++) << a, c, d;
    }
  }
  if (!loop) {
    const int c0 = n * m, c1 = n * m + 1;
    t.V.row(c0) = C.front();
    t.V.row(c1) = C.back();
    for (int j = 0; j < m; ++j) {
      const int j1 = (j + 1) % m;
      t.F.row(f++) << c0, j1, j;
      t.F.row(f++) << c1, (n - 1) * m + j, (n - 1) * m + j1;
    }
  }
  return t;
}

// Moves the mesh so its bounding box starts at the origin.
void move_to_origin(TriMesh& mesh) {
  const BoundingBox box = bounding_box(mesh.V);
  mesh.V.rowwise() -= box.min.transpose();
}

// --- chain mail ---------------------------------------------------------------------------
// Layout in units of the ring radius, chosen by scanning tilt and spacings for the largest
// minimum distance between the centre circles of a ring and its neighbours (0.5).
constexpr double kMailTilt = 0.6;
constexpr double kMailPitchX = 1.25;
constexpr double kMailPitchY = 1.25;
constexpr double kMailMaxWire = 0.2;

void check_mail(const ChainMailOptions& o) {
  MQ_CHECK(o.rows >= 1 && o.cols >= 1, InvalidInput, "chain mail: rows and cols must be >= 1");
  MQ_CHECK(o.ring_segments >= 3 && o.wire_segments >= 3, InvalidInput,
           "chain mail: ring_segments and wire_segments must be >= 3");
  MQ_CHECK(o.ring_radius > 0 && o.wire_radius > 0, InvalidInput,
           "chain mail: ring_radius and wire_radius must be positive");
  MQ_CHECK(o.wire_radius <= kMailMaxWire * o.ring_radius, InvalidInput, "chain mail: wire_radius ",
           o.wire_radius, " exceeds ", kMailMaxWire, " * ring_radius: rings would intersect");
}

// --- apples -------------------------------------------------------------------------------
// Profile (rho, z) of a unit apple from the bottom pole to the stem tip.
std::vector<Vector2d> apple_profile(int body_samples, double stem_radius, double stem_height) {
  const auto rho = [](double t) { return std::sin(t) * (1.0 - 0.12 * std::cos(t)); };
  const auto z = [](double t) {
    return -0.85 * std::cos(t) + 0.12 * std::exp(-(t * t) / 0.12) -
           0.25 * std::exp(-((M_PI - t) * (M_PI - t)) / 0.12);
  };
  // Body ends where the radius has shrunk to the stem radius, at the bottom of the top dimple.
  double t_end = M_PI - stem_radius;
  for (int it = 0; it < 40; ++it)
    t_end = M_PI - std::asin(std::min(1.0, stem_radius / (1.0 - 0.12 * std::cos(t_end))));
  std::vector<Vector2d> p;
  for (int i = 0; i <= body_samples; ++i) {
    const double t = t_end * i / body_samples;
    p.emplace_back(rho(t), z(t));
  }
  const double z_end = p.back().y();
  p.emplace_back(0.85 * stem_radius, z_end + stem_height);
  p.emplace_back(0.0, z_end + stem_height + 0.2 * stem_radius);
  p.front().x() = 0.0;
  return p;
}

// Surface of revolution of the profile (first and last points on the axis), with the radius
// modulated by five bottom lobes: rho * (1 + lobe * cos(5 theta) * w), w fading to the top.
TriMesh revolve(const std::vector<Vector2d>& p, int m, double lobe) {
  const int n = static_cast<int>(p.size());
  const int rings = n - 2;
  TriMesh t;
  t.V.resize(rings * m + 2, 3);
  const double z_min = p.front().y(), z_span = p.back().y() - z_min;
  for (int i = 1; i <= rings; ++i) {
    const double w = std::pow(std::max(0.0, 1.0 - (p[i].y() - z_min) / z_span), 2);
    for (int j = 0; j < m; ++j) {
      const double th = 2 * M_PI * j / m;
      const double r = p[i].x() * (1 + lobe * std::cos(5 * th) * w);
      t.V.row((i - 1) * m + j) << r * std::cos(th), r * std::sin(th), p[i].y();
    }
  }
  const int bottom = rings * m, top = rings * m + 1;
  t.V.row(bottom) << 0, 0, p.front().y();
  t.V.row(top) << 0, 0, p.back().y();
  t.F.resize(2 * (rings - 1) * m + 2 * m, 3);
  int f = 0;
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < m; ++j) {
      const int j1 = (j + 1) % m;
      const int a = i * m + j, b = i * m + j1, c = (i + 1) * m + j1, d = (i + 1) * m + j;
      t.F.row(f++) << a, b, c;
      t.F.row(f++) << a, c, d;
    }
  for (int j = 0; j < m; ++j) {
    const int j1 = (j + 1) % m;
    t.F.row(f++) << bottom, j1, j;
    t.F.row(f++) << top, (rings - 1) * m + j, (rings - 1) * m + j1;
  }
  return t;
}

// --- ivy ----------------------------------------------------------------------------------
// Five-lobed ivy outline radius at angle beta from the leaf tip, for unit leaf size.
double ivy_outline(double beta) {
  const double lobes[5][2] = {{0.0, 1.0}, {1.15, 0.72}, {-1.15, 0.72}, {2.2, 0.5}, {-2.2, 0.5}};
  double r = 0.22;
  for (const auto& l : lobes) {
    double d = std::remainder(beta - l[0], 2 * M_PI);
    r += 0.62 * l[1] * std::exp(-d * d / (2 * 0.32 * 0.32));
  }
  return r;
}

// A thin closed leaf: the outline fanned from its centre c on a bottom and a top surface,
// joined by a side wall. Heights follow z_bottom(p); the top is thickness above, the centre
// of the top raised a little more (midrib).
template <typename HeightFn>
TriMesh leaf_mesh(const Vector2d& c, const Vector2d& axis, double size, double thickness, int m,
                  HeightFn z_bottom) {
  const Vector2d perp(-axis.y(), axis.x());
  TriMesh t;
  t.V.resize(2 * m + 2, 3);
  for (int j = 0; j < m; ++j) {
    const double beta = 2 * M_PI * j / m;
    const Vector2d q =
        c + size * ivy_outline(beta) * (std::cos(beta) * axis + std::sin(beta) * perp);
    const double zb = z_bottom(q);
    t.V.row(j) << q.x(), q.y(), zb;
    t.V.row(m + j) << q.x(), q.y(), zb + thickness;
  }
  const int cb = 2 * m, ct = 2 * m + 1;
  t.V.row(cb) << c.x(), c.y(), z_bottom(c);
  t.V.row(ct) << c.x(), c.y(), z_bottom(c) + 1.5 * thickness;
  t.F.resize(4 * m, 3);
  int f = 0;
  for (int j = 0; j < m; ++j) {
    const int j1 = (j + 1) % m;
    t.F.row(f++) << ct, m + j, m + j1;
    t.F.row(f++) << cb, j1, j;
    t.F.row(f++) << j, j1, m + j1;
    t.F.row(f++) << j, m + j1, m + j;
  }
  return t;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

double chainmail_period_x(const ChainMailOptions& o) {
  check_mail(o);
  return 2 * kMailPitchX * o.ring_radius;
}

double chainmail_period_y(const ChainMailOptions& o) {
  check_mail(o);
  return kMailPitchY * o.ring_radius;
}

TriMesh chainmail_4in1(const ChainMailOptions& o) {
  check_mail(o);
  const double R = o.ring_radius;
  TriMesh mail;
  const int n = o.ring_segments;
  std::vector<Vector3d> C(n), T(n);
  for (int c = 0; c < o.cols; ++c)
    for (int k = 0; k < o.rows; ++k) {
      const double sgn = (c % 2 == 0) ? 1.0 : -1.0;
      const Vector3d centre(c * kMailPitchX * R, (k + (c % 2) * 0.5) * kMailPitchY * R, 0.0);
      // Ring plane spanned by e1 = x and e2 = y tilted by +-kMailTilt about x.
      const Vector3d e1 = Vector3d::UnitX();
      const Vector3d e2(0, std::cos(kMailTilt), sgn * std::sin(kMailTilt));
      for (int i = 0; i < n; ++i) {
        const double t = 2 * M_PI * i / n;
        C[i] = centre + R * (std::cos(t) * e1 + std::sin(t) * e2);
        T[i] = -std::sin(t) * e1 + std::cos(t) * e2;
      }
      TriMesh ring = tube_mesh(C, T, e1.cross(e2), o.wire_radius, o.wire_segments, true);
      set_single_kind(ring, "ring");
      if (mail.empty())
        mail = ring;
      else
        append_mesh(mail, ring);
    }
  move_to_origin(mail);
  return mail;
}

namespace {

// Square mail layout in units of the flat ring radius: pitch 2.5 leaves 0.26 between flat rings of
// wire 0.12 (0.2 at the largest wire, 0.15); a connector of radius 0.6 centred half-way crosses the
// flat rings' plane 0.65 from each centre, 0.35 inside their wire circles, and their wires pass
// through its hole 0.25 from its centre, 0.35 inside its wire circle: 0.35 - 2 * 0.15 = 0.05 is the
// least clearance. Connectors along x and along y are 1.77 apart, more than their 1.5 reach.
constexpr double kSquarePitch = 2.5;
constexpr double kSquareConnector = 0.6;
constexpr double kSquareMaxWire = 0.15;

void check_square(const SquareMailOptions& o) {
  MQ_CHECK(o.rows >= 1 && o.cols >= 1, InvalidInput,
           "square chain mail: rows and cols must be >= 1");
  MQ_CHECK(o.ring_segments >= 3 && o.wire_segments >= 3, InvalidInput,
           "square chain mail: ring_segments and wire_segments must be >= 3");
  MQ_CHECK(o.ring_radius > 0 && o.wire_radius > 0, InvalidInput,
           "square chain mail: ring_radius and wire_radius must be positive");
  MQ_CHECK(o.wire_radius <= kSquareMaxWire * o.ring_radius, InvalidInput,
           "square chain mail: wire_radius ", o.wire_radius, " exceeds ", kSquareMaxWire,
           " * ring_radius: rings would intersect");
}

// A ring of wire centre radius r about `centre` in the plane spanned by unit e1, e2.
TriMesh ring_in_plane(const Vector3d& centre, const Vector3d& e1, const Vector3d& e2, double r,
                      const SquareMailOptions& o) {
  const int n = o.ring_segments;
  std::vector<Vector3d> C(n), T(n);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    C[i] = centre + r * (std::cos(t) * e1 + std::sin(t) * e2);
    T[i] = -std::sin(t) * e1 + std::cos(t) * e2;
  }
  return tube_mesh(C, T, e1.cross(e2), o.wire_radius, o.wire_segments, true);
}

}  // namespace

double chainmail_square_period(const SquareMailOptions& o) {
  check_square(o);
  return kSquarePitch * o.ring_radius;
}

TriMesh chainmail_square(const SquareMailOptions& o) {
  check_square(o);
  const double R = o.ring_radius, P = kSquarePitch * R, Rc = kSquareConnector * R;
  TriMesh mail;
  const auto add = [&](TriMesh ring, const char* kind) {
    set_single_kind(ring, kind);
    if (mail.empty())
      mail = std::move(ring);
    else
      append_mesh(mail, ring);
  };
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  for (int k = 0; k < o.rows; ++k)
    for (int c = 0; c < o.cols; ++c)
      add(ring_in_plane(Vector3d(c * P, k * P, 0), x, y, R, o), "ring");
  // Upright connectors: in the xz plane between neighbours along x, in the yz plane along y.
  for (int k = 0; k < o.rows; ++k)
    for (int c = 0; c + 1 < o.cols; ++c)
      add(ring_in_plane(Vector3d((c + 0.5) * P, k * P, 0), x, z, Rc, o), "connector");
  for (int k = 0; k + 1 < o.rows; ++k)
    for (int c = 0; c < o.cols; ++c)
      add(ring_in_plane(Vector3d(c * P, (k + 0.5) * P, 0), y, z, Rc, o), "connector");
  move_to_origin(mail);
  return mail;
}

TriMesh plain_weave(const WeaveOptions& o) {
  MQ_CHECK(o.threads_x >= 1 && o.threads_y >= 1, InvalidInput,
           "plain weave: threads_x and threads_y must be >= 1");
  MQ_CHECK(o.segments_per_cell >= 2 && o.tube_segments >= 3, InvalidInput,
           "plain weave: segments_per_cell must be >= 2 and tube_segments >= 3");
  MQ_CHECK(o.spacing > 0 && o.thread_radius > 0, InvalidInput,
           "plain weave: spacing and thread_radius must be positive");
  MQ_CHECK(o.thread_radius <= 0.17 * o.spacing, InvalidInput, "plain weave: thread_radius ",
           o.thread_radius, " exceeds 0.17 * spacing: threads would intersect");
  const double s = o.spacing, A = 1.2 * o.thread_radius, w = M_PI / s;
  TriMesh cloth;
  // dir 0: warp along x at y = j s; dir 1: weft along y at x = i s.
  for (int dir = 0; dir < 2; ++dir) {
    const int count = dir == 0 ? o.threads_x : o.threads_y;
    const int crossings = dir == 0 ? o.threads_y : o.threads_x;
    const int n = crossings * o.segments_per_cell + 1;  // samples over [-s/2, (crossings-1/2) s]
    for (int j = 0; j < count; ++j) {
      const double amp = (dir == 0 ? 1.0 : -1.0) * (j % 2 == 0 ? 1.0 : -1.0) * A;
      std::vector<Vector3d> C(n), T(n);
      for (int k = 0; k < n; ++k) {
        const double u = -0.5 * s + s * k / o.segments_per_cell;
        const double z = amp * std::cos(w * u), dz = -amp * w * std::sin(w * u);
        C[k] = dir == 0 ? Vector3d(u, j * s, z) : Vector3d(j * s, u, z);
        T[k] = dir == 0 ? Vector3d(1, 0, dz) : Vector3d(0, 1, dz);
      }
      TriMesh thread = tube_mesh(C, T, Vector3d::UnitZ(), o.thread_radius, o.tube_segments, false);
      set_single_kind(thread, dir == 0 ? "thread_x" : "thread_y");
      if (cloth.empty())
        cloth = thread;
      else
        append_mesh(cloth, thread);
    }
  }
  move_to_origin(cloth);
  return cloth;
}

TriMesh apple_layer(const AppleOptions& o) {
  MQ_CHECK(o.count >= 1, InvalidInput, "apple layer: count must be >= 1");
  MQ_CHECK(o.resolution >= 6, InvalidInput, "apple layer: resolution must be >= 6");
  MQ_CHECK(o.mean_radius > 0, InvalidInput, "apple layer: mean_radius must be positive");
  MQ_CHECK(o.radius_variation >= 0 && o.radius_variation <= 0.9, InvalidInput,
           "apple layer: radius_variation must be in [0, 0.9]");
  std::mt19937_64 rng(o.seed);
  const int body_samples = std::max(4, o.resolution * 5 / 8);
  std::vector<TriMesh> apples(o.count);
  std::vector<double> reach(o.count);  // bounding-circle radius about the z axis
  double area = 0;
  for (int a = 0; a < o.count; ++a) {
    const double r = o.mean_radius * (1 + o.radius_variation * uniform(rng, -1, 1));
    const double squash = uniform(rng, 0.88, 1.0), rot = uniform(rng, 0, 2 * M_PI);
    TriMesh m = revolve(apple_profile(body_samples, 0.05, uniform(rng, 0.2, 0.32)), o.resolution,
                        uniform(rng, 0.02, 0.05));
    const Eigen::Matrix3d S = (Eigen::AngleAxisd(rot, Vector3d::UnitZ()).toRotationMatrix() *
                               Eigen::Vector3d(r, r, r * squash).asDiagonal());
    for (int v = 0; v < m.num_vertices(); ++v) m.V.row(v) = (S * m.V.row(v).transpose());
    m.V.col(2).array() -= m.V.col(2).minCoeff();  // rest on z = 0
    reach[a] = m.V.leftCols(2).rowwise().norm().maxCoeff();
    area += M_PI * reach[a] * reach[a];
    apples[a] = std::move(m);
  }
  // Dart throwing in a square of side L, grown by 5% whenever an apple cannot be placed.
  const double gap = 0.02 * o.mean_radius;
  double L = std::sqrt(area / 0.45);
  std::vector<Vector2d> pos;
  while (static_cast<int>(pos.size()) < o.count) {
    pos.clear();
    for (int a = 0; a < o.count; ++a) {
      bool placed = false;
      const double lo = reach[a], hi = std::max(lo, L - reach[a]);
      for (int attempt = 0; attempt < 2000 && !placed; ++attempt) {
        const Vector2d p(uniform(rng, lo, hi), uniform(rng, lo, hi));
        placed = true;
        for (int b = 0; b < a && placed; ++b)
          placed = (p - pos[b]).norm() > reach[a] + reach[b] + gap;
        if (placed) pos.push_back(p);
      }
      if (!placed) break;
    }
    if (static_cast<int>(pos.size()) < o.count) L *= 1.05;
  }
  TriMesh layer;
  for (int a = 0; a < o.count; ++a) {
    apples[a].V.col(0).array() += pos[a].x();
    apples[a].V.col(1).array() += pos[a].y();
    set_single_kind(apples[a], "apple");
    if (layer.empty())
      layer = apples[a];
    else
      append_mesh(layer, apples[a]);
  }
  move_to_origin(layer);
  return layer;
}

TriMesh ivy_section(const IvyOptions& o) {
  MQ_CHECK(o.length > 0, InvalidInput, "ivy section: length must be positive");
  MQ_CHECK(o.leaves >= 0, InvalidInput, "ivy section: leaves must be >= 0");
  MQ_CHECK(o.leaf_size > 0, InvalidInput, "ivy section: leaf_size must be positive");
  std::mt19937_64 rng(o.seed);
  const double rv = 0.06, wave = 0.3, wavelength = uniform(rng, 2.5, 3.5);
  const double phase = uniform(rng, 0, 2 * M_PI);
  const auto vine_y = [&](double x) { return wave * std::sin(2 * M_PI * x / wavelength + phase); };
  const int n = std::max(8, static_cast<int>(std::ceil(12 * o.length))) + 1;
  std::vector<Vector3d> C(n), T(n);
  for (int k = 0; k < n; ++k) {
    const double x = o.length * k / (n - 1);
    C[k] = Vector3d(x, vine_y(x), rv);
    T[k] =
        Vector3d(1, wave * 2 * M_PI / wavelength * std::cos(2 * M_PI * x / wavelength + phase), 0);
  }
  TriMesh ivy = tube_mesh(C, T, Vector3d::UnitZ(), rv, 8, false);
  set_single_kind(ivy, "vine");
  const TriMesh vine = ivy;

  std::vector<TriMesh> placed;
  const double pitch = o.length / std::max(1, o.leaves);
  for (int i = 0; i < o.leaves; ++i) {
    const double side = (i % 2 == 0) ? 1.0 : -1.0;
    TriMesh leaf;
    bool ok = false;
    double lift = 0;
    for (int attempt = 0; !ok; ++attempt) {
      // After 20 failed placements raise the whole leaf step by step: it ends up clear of all.
      if (attempt > 0 && attempt % 20 == 0) lift += rv;
      const double size = o.leaf_size * uniform(rng, 0.75, 1.15);
      const double x = (i + 0.5) * pitch + uniform(rng, -0.2, 0.2) * pitch;
      const double angle = side * M_PI / 2 + uniform(rng, -0.45, 0.45);
      const Vector2d axis(std::cos(angle), std::sin(angle));
      const Vector2d base(x, vine_y(x));
      const Vector2d c = base + (rv + 0.03 + size * ivy_outline(M_PI)) * axis;
      // Bottom slopes from above the vine down to the plane at the leaf tip.
      const double tip = size * ivy_outline(0.0), back = size * 0.7;
      const double z_hi = 2 * rv + 0.03, slope = z_hi / (tip + back);
      const auto z_bottom = [&](const Vector2d& p) {
        return lift + std::max(0.0, slope * (tip - (p - c).dot(axis)));
      };
      leaf = leaf_mesh(c, axis, size, 0.03 * size / 0.8, 48, z_bottom);
      ok = !meshes_intersect(leaf, vine);
      for (std::size_t p = 0; p < placed.size() && ok; ++p) ok = !meshes_intersect(leaf, placed[p]);
    }
    set_single_kind(leaf, "leaf");
    placed.push_back(leaf);
    append_mesh(ivy, leaf);
  }
  move_to_origin(ivy);
  return ivy;
}

namespace {

// The parts of an ivy section the wind moves: its vine (the element longest along x: its
// vertices, where it starts, its length and radius) and each leaf (its vertices, the point it
// turns about, its axis from there in the plane, its element).
struct IvyParts {
  struct Leaf {
    int element = 0;
    std::vector<int> vertices;
    Vector3d pivot = Vector3d::Zero(), axis = Vector3d::UnitX();
  };
  int vine = 0;
  std::vector<int> vine_vertices;
  double x0 = 0, length = 1, radius = 0;
  std::vector<Leaf> leaves;
};

// The leaf's pivot: the line across its back (its point least far along its axis, at the
// height of its vertex nearest the vine), so that turning it lifts every point, none sinking
// towards the vine. false for a leaf with no extent in the plane.
bool set_leaf_pivot(const TriMesh& ivy, const std::vector<int>& vine, IvyParts::Leaf& leaf) {
  int pivot = leaf.vertices.front();
  double nearest = kInf;
  Vector3d centroid = Vector3d::Zero();
  for (const int v : leaf.vertices) {
    centroid += ivy.V.row(v).transpose();
    for (const int w : vine) {
      const double d = (ivy.V.row(v) - ivy.V.row(w)).squaredNorm();
      if (d < nearest) nearest = d, pivot = v;
    }
  }
  centroid /= static_cast<double>(leaf.vertices.size());
  const Vector3d p = ivy.V.row(pivot).transpose();
  Vector3d axis = centroid - p;
  axis.z() = 0;
  if (!(axis.norm() > 0)) return false;
  leaf.axis = axis.normalized();
  double back = 0;
  for (const int v : leaf.vertices)
    back = std::min(back, (ivy.V.row(v).transpose() - p).dot(leaf.axis));
  leaf.pivot = p + back * leaf.axis;
  return true;
}

IvyParts ivy_parts(const TriMesh& ivy) {
  const int nv = ivy.num_vertices();
  std::vector<int> face_component;
  const int n = connected_components(ivy.F, nv, face_component);
  MQ_CHECK(n >= 2, InvalidInput, "ivy wind: the ivy needs a vine and at least one leaf");
  std::vector<std::vector<int>> vertices(static_cast<size_t>(n));
  std::vector<int> component(static_cast<size_t>(nv), -1);
  for (int f = 0; f < ivy.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      component[static_cast<size_t>(ivy.F(f, k))] = face_component[static_cast<size_t>(f)];
  for (int v = 0; v < nv; ++v)
    if (component[static_cast<size_t>(v)] >= 0)
      vertices[static_cast<size_t>(component[static_cast<size_t>(v)])].push_back(v);
  const auto extent = [&](int c, int axis) {
    double lo = kInf, hi = -kInf;
    for (const int v : vertices[static_cast<size_t>(c)]) {
      lo = std::min(lo, ivy.V(v, axis));
      hi = std::max(hi, ivy.V(v, axis));
    }
    return std::pair{lo, hi};
  };
  IvyParts parts;
  for (int c = 1; c < n; ++c) {
    const auto [lo, hi] = extent(c, 0);
    const auto [vlo, vhi] = extent(parts.vine, 0);
    if (hi - lo > vhi - vlo) parts.vine = c;
  }
  parts.vine_vertices = vertices[static_cast<size_t>(parts.vine)];
  const auto [x0, x1] = extent(parts.vine, 0);
  const auto [z0, z1] = extent(parts.vine, 2);
  parts.x0 = x0;
  parts.length = std::max(x1 - x0, 1e-300);
  parts.radius = 0.5 * (z1 - z0);
  for (int c = 0; c < n; ++c) {
    if (c == parts.vine) continue;
    IvyParts::Leaf leaf;
    leaf.element = c;
    leaf.vertices = vertices[static_cast<size_t>(c)];
    if (set_leaf_pivot(ivy, parts.vine_vertices, leaf)) parts.leaves.push_back(std::move(leaf));
  }
  return parts;
}

// Frame `frame` of the wind on `ivy` (ivy_wind), each element's motion scaled by its amplitude.
MatrixX3d ivy_wind_positions(const TriMesh& ivy, const IvyParts& parts, int frame,
                             const IvyWindOptions& o, const std::vector<double>& amplitude) {
  // The gust: zero at the loop's ends with zero slope, a wave one section long along x.
  const double t = static_cast<double>(frame) / o.frames;
  const double gust = std::pow(std::sin(M_PI * t), 2);
  const auto wave = [&](double x, double shift) {
    return std::sin(2 * M_PI * (2 * t - (x - parts.x0) / parts.length) + shift);
  };
  const double a_vine = amplitude[static_cast<size_t>(parts.vine)];
  const auto sway = [&](double x) {
    return Vector3d(0, a_vine * o.vine_sway * parts.radius * gust * wave(x, 0), 0);
  };
  MatrixX3d out = ivy.V;
  if (gust == 0) return out;
  if (a_vine > 0 && o.vine_sway > 0)
    for (const int v : parts.vine_vertices) out.row(v) += sway(ivy.V(v, 0)).transpose();
  for (const IvyParts::Leaf& leaf : parts.leaves) {
    const double a = amplitude[static_cast<size_t>(leaf.element)];
    if (a == 0) continue;
    const Vector3d& p = leaf.pivot;
    // Lifting about axis x z raises the tip; rolling about the axis tilts it sideways.
    const double lift = a * o.lift_angle * gust * (0.5 + 0.5 * wave(p.x(), 0));
    const double roll = o.roll_share * lift * wave(p.x(), 1);
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(lift, leaf.axis.cross(Vector3d::UnitZ()).normalized()) *
         Eigen::AngleAxisd(roll, leaf.axis))
            .toRotationMatrix();
    const Vector3d carried = sway(p.x());
    for (const int v : leaf.vertices)
      out.row(v) = (p + carried + R * (ivy.V.row(v).transpose() - p)).transpose();
  }
  return out;
}

}  // namespace

std::vector<TriMesh> ivy_wind(const TriMesh& ivy, const IvyWindOptions& o) {
  MQ_CHECK(o.frames >= 1, InvalidInput, "ivy wind: frames must be >= 1");
  MQ_CHECK(o.lift_angle >= 0 && o.roll_share >= 0 && o.vine_sway >= 0, InvalidInput,
           "ivy wind: amplitudes must be >= 0");
  const IvyParts parts = ivy_parts(ivy);
  // Leaves that would meet a neighbour or the vine in some frame move less (settled_amplitudes).
  const std::vector<double> amplitude = settled_amplitudes(
      ivy.V, ivy.F, o.frames,
      [&](int k, const std::vector<double>& a) { return ivy_wind_positions(ivy, parts, k, o, a); });
  std::vector<TriMesh> frames(static_cast<size_t>(o.frames), ivy);
  for (int k = 1; k < o.frames; ++k)
    frames[static_cast<size_t>(k)].V = ivy_wind_positions(ivy, parts, k, o, amplitude);
  return frames;
}

}  // namespace mq
