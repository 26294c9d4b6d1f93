#include "core/output/render.h"

#include <embree3/rtcore.h>
#include <png.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <system_error>

#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"

namespace mq {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGolden = 0.6180339887498949;  // 1/phi: successive multiples spread evenly
constexpr double kFill = 0.8;                   // fraction of the image the object spans
constexpr double kCreaseDeg = 75;               // normals are not averaged across sharper creases

struct DeviceDeleter {
  void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
};
struct SceneDeleter {
  void operator()(RTCScene s) const { rtcReleaseScene(s); }
};
using DevicePtr = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using ScenePtr = std::unique_ptr<RTCSceneTy, SceneDeleter>;

double frac(double x) { return x - std::floor(x); }

double srgb_to_linear(double c) { return std::pow(c, 2.2); }

unsigned char linear_to_byte(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return static_cast<unsigned char>(std::floor(255.0 * std::pow(c, 1.0 / 2.2) + 0.5));
}

// HSV (each in [0,1]) to display-space RGB.
Vector3d hsv_to_rgb(double h, double s, double v) {
  const double h6 = 6.0 * frac(h);
  const int i = static_cast<int>(h6) % 6;
  const double f = h6 - std::floor(h6);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (i) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

// Linear albedo of component c. Hues follow the golden-ratio sequence, so components with
// nearby ids (usually spatial neighbours) get clearly different hues.
Vector3d element_albedo(int c, bool color_elements) {
  Vector3d rgb(0.78, 0.76, 0.72);  // neutral clay
  if (color_elements) {
    const double h = frac(0.58 + c * kGolden);
    const double s = 0.45 + 0.2 * frac(0.3 + c * 0.7548776662466927);
    const double v = 0.78 + 0.14 * frac(0.5 + c * 0.5698402909980532);
    rgb = hsv_to_rgb(h, s, v);
  }
  return rgb.unaryExpr([](double x) { return srgb_to_linear(x); });
}

void check_mesh(const TriMesh& mesh) {
  MQ_CHECK(!mesh.empty(), InvalidInput, "render: the mesh has no faces");
  MQ_CHECK(mesh.V.allFinite(), InvalidInput,
           "render: the mesh has a non-finite (NaN or infinite) vertex coordinate");
  MQ_CHECK(mesh.F.minCoeff() >= 0 && mesh.F.maxCoeff() < mesh.num_vertices(), InvalidInput,
           "render: a face index is outside [0, ", mesh.num_vertices(), ")");
}

// Per component: true when every manifold edge is used in opposite directions by its two faces
// and no edge has more than two faces, i.e. vertex normals are meaningful.
std::vector<char> coherently_oriented(const MatrixX3i& F, int num_vertices,
                                      const std::vector<int>& face_component, int num_components) {
  std::vector<char> ok(num_components, 1);
  const EdgeTopology topo = edge_topology(F, num_vertices);
  auto forward = [&](int f, int e) {  // does face f traverse edge e from E(e,0) to E(e,1)?
    for (int k = 0; k < 3; ++k)
      if (topo.FE(f, k) == e) return F(f, k) == topo.E(e, 0);
    return false;
  };
  for (int e = 0; e < topo.num_edges(); ++e) {
    const int degree = topo.edge_faces.degree(e);
    if (degree <= 1) continue;
    const int* faces = topo.edge_faces.begin(e);
    if (degree > 2 || forward(faces[0], e) == forward(faces[1], e))
      for (int i = 0; i < degree; ++i) ok[face_component[faces[i]]] = 0;
  }
  return ok;
}

// Smooth-shading normals at each face corner (row 3f+k): the area-weighted average of the
// normals of the faces around the corner's vertex that are within the crease angle of face f.
// Zero rows for faces of flat-shaded components or when nothing qualifies.
MatrixX3d corner_normals(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& NF,
                         const std::vector<int>& face_component, const std::vector<char>& smooth) {
  const Eigen::VectorXd A = face_areas(V, F);
  const Adjacency vf = vertex_faces(F, static_cast<int>(V.rows()));
  const double cos_crease = std::cos(kCreaseDeg * kPi / 180);
  MatrixX3d CN = MatrixX3d::Zero(3 * F.rows(), 3);
  tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(F.rows())),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int f = r.begin(); f < r.end(); ++f) {
                        if (!smooth[face_component[f]]) continue;
                        const Vector3d nf = NF.row(f);
                        for (int k = 0; k < 3; ++k) {
                          Vector3d sum = Vector3d::Zero();
                          for (const int* g = vf.begin(F(f, k)); g != vf.end(F(f, k)); ++g)
                            if (nf.dot(NF.row(*g)) >= cos_crease) sum += A(*g) * NF.row(*g);
                          const double len = sum.norm();
                          if (len > 0) CN.row(3 * f + k) = sum / len;
                        }
                      }
                    });
  return CN;
}

struct Camera {
  Vector3d eye, forward, right, up;
  double tan_half_w = 0, tan_half_h = 0;
};

// Orbit camera looking at the object; points are in the centred local frame.
Camera frame_camera(const MatrixX3d& P, const std::vector<char>& referenced, const RenderOptions& o,
                    double radius) {
  const Vector3d up_w = Vector3d::Unit(o.up_axis);
  // (h1, up, h2) is right-handed: for y up these are x and z, and azimuth 0 looks down -z.
  const Vector3d h1 = Vector3d::Unit((o.up_axis + 2) % 3), h2 = Vector3d::Unit((o.up_axis + 1) % 3);
  const double az = o.azimuth_deg * kPi / 180, el = o.elevation_deg * kPi / 180;
  const Vector3d w =
      std::cos(el) * (std::sin(az) * h1 + std::cos(az) * h2) + std::sin(el) * up_w;  // to eye
  Camera cam;
  cam.forward = -w;
  cam.right = cam.forward.cross(up_w).normalized();
  cam.up = cam.right.cross(cam.forward);
  cam.tan_half_h = std::tan(0.5 * o.fov_deg * kPi / 180);
  cam.tan_half_w = cam.tan_half_h * o.width / o.height;

  // Centre the projected extent, then back off until every vertex is inside kFill of the view.
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  for (int i = 0; i < P.rows(); ++i) {
    if (!referenced[i]) continue;
    const double x = cam.right.dot(P.row(i)), y = cam.up.dot(P.row(i));
    xmin = std::min(xmin, x), xmax = std::max(xmax, x);
    ymin = std::min(ymin, y), ymax = std::max(ymax, y);
  }
  const double cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
  double dist = 0;
  for (int i = 0; i < P.rows(); ++i) {
    if (!referenced[i]) continue;
    const Vector3d p = P.row(i);
    const double x = cam.right.dot(p) - cx, y = cam.up.dot(p) - cy, z = w.dot(p);
    dist = std::max({dist, z + 0.05 * radius, z + std::abs(x) / (kFill * cam.tan_half_w),
                     z + std::abs(y) / (kFill * cam.tan_half_h)});
  }
  cam.eye = cx * cam.right + cy * cam.up + dist * w;
  return cam;
}

// Fixed sub-pixel sample positions in [0,1)^2: stratified in x, golden-ratio sequence in y.
std::vector<Eigen::Vector2d> sample_pattern(int n) {
  std::vector<Eigen::Vector2d> s(n);
  for (int k = 0; k < n; ++k) s[k] = {(k + 0.5) / n, frac(0.5 + k * kGolden)};
  return s;
}

RTCRay make_ray(const Vector3d& org, const Vector3d& dir, float tnear) {
  RTCRay ray;
  ray.org_x = static_cast<float>(org.x());
  ray.org_y = static_cast<float>(org.y());
  ray.org_z = static_cast<float>(org.z());
  ray.dir_x = static_cast<float>(dir.x());
  ray.dir_y = static_cast<float>(dir.y());
  ray.dir_z = static_cast<float>(dir.z());
  ray.tnear = tnear;
  ray.tfar = std::numeric_limits<float>::infinity();
  ray.time = 0;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

// The mesh in a frame centred on its bounding box, so that Embree's floats keep their
// precision, with the vertices its faces use and the radius of the box.
struct CentredMesh {
  MatrixX3d P;
  std::vector<char> referenced;
  double radius = 1;
};

CentredMesh centred_mesh(const TriMesh& mesh) {
  CentredMesh c;
  const BoundingBox box = bounding_box(mesh.V, mesh.F);
  const Vector3d center = box.center();
  c.P = mesh.V.rowwise() - center.transpose();
  c.radius = 0.5 * box.extent().norm();
  if (!(c.radius > 0)) c.radius = 1;  // every vertex coincides: nothing will be hit
  c.referenced.assign(mesh.num_vertices(), 0);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) c.referenced[mesh.F(f, k)] = 1;
  return c;
}

// The linear albedo of each component: its hue (or the clay colour), a given colour, or clay
// from neutral_from on.
std::vector<Vector3d> element_albedos(int num_components, const RenderOptions& o) {
  MQ_CHECK(o.element_colors.empty() ||
               static_cast<int>(o.element_colors.size()) == num_components ||
               (o.neutral_from >= 0 && static_cast<int>(o.element_colors.size()) == o.neutral_from),
           InvalidInput, "render: ", o.element_colors.size(), " element colours for ",
           num_components, " elements");
  std::vector<Vector3d> albedo(num_components);
  for (int c = 0; c < num_components; ++c) {
    albedo[c] = element_albedo(c, o.color_elements);
    if (!o.element_colors.empty() && c < static_cast<int>(o.element_colors.size()))
      for (int k = 0; k < 3; ++k) albedo[c](k) = srgb_to_linear(o.element_colors[c][k] / 255.0);
    if (o.neutral_from >= 0 && c >= o.neutral_from) albedo[c] = element_albedo(c, false);
  }
  return albedo;
}

// An Embree device and its committed scene of one triangle geometry.
struct EmbreeScene {
  DevicePtr device;
  ScenePtr scene;
};

EmbreeScene build_scene(const MatrixX3d& P, const MatrixX3i& F) {
  const int nv = static_cast<int>(P.rows()), nf = static_cast<int>(F.rows());
  EmbreeScene s;
  s.device.reset(rtcNewDevice("verbose=0"));
  MQ_CHECK(s.device, InternalError, "render: cannot create the Embree device (error ",
           static_cast<int>(rtcGetDeviceError(nullptr)), ")");
  s.scene.reset(rtcNewScene(s.device.get()));
  rtcSetSceneFlags(s.scene.get(), RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geom = rtcNewGeometry(s.device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nf));
  if (vb && ib) {
    for (int i = 0; i < nv; ++i)
      for (int k = 0; k < 3; ++k) vb[3 * i + k] = static_cast<float>(P(i, k));
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) ib[3 * f + k] = static_cast<unsigned>(F(f, k));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(s.scene.get(), geom);
  }
  rtcReleaseGeometry(geom);
  MQ_CHECK(vb && ib, InternalError, "render: Embree could not allocate the mesh buffers");
  rtcCommitScene(s.scene.get());
  const RTCError err = rtcGetDeviceError(s.device.get());
  MQ_CHECK(err == RTC_ERROR_NONE, InternalError, "render: Embree failed to build the scene (error ",
           static_cast<int>(err), ")");
  return s;
}

// Shading of camera rays: Lambert from a key light and a headlight, a little ambient and a
// soft rim, hard shadows from the key light, and the optional shadow-catching floor.
class Shader {
 public:
  Shader(RTCScene scene, const CentredMesh& m, const MatrixX3i& F, const MatrixX3d& NF,
         const MatrixX3d& CN, const std::vector<int>& face_component,
         const std::vector<Vector3d>& albedo, const Camera& cam, const RenderOptions& o)
      : scene_(scene),
        m_(m),
        F_(F),
        NF_(NF),
        CN_(CN),
        face_component_(face_component),
        albedo_(albedo),
        cam_(cam),
        o_(o),
        key_((-0.65 * cam.right + 0.7 * cam.up - 0.3 * cam.forward).normalized()),
        head_(-cam.forward),
        bg_lin_(srgb_to_linear(o.background[0] / 255.0), srgb_to_linear(o.background[1] / 255.0),
                srgb_to_linear(o.background[2] / 255.0)),
        up_w_(Vector3d::Unit(o.up_axis)),
        eps_(static_cast<float>(1e-4 * m.radius)) {
    for (int i = 0; i < m.P.rows(); ++i)
      if (m.referenced[i]) ground_h_ = std::min(ground_h_, up_w_.dot(m.P.row(i)));
  }

  // Linear radiance along one camera ray.
  Vector3d shade(const Vector3d& dir) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray = make_ray(cam_.eye, dir, 0.0f);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx, &rh);
    const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    if (!hit || o_.ground_plane) {
      // Shadow-catching floor touching the object from below, fading into the background.
      const double dz = dir.dot(up_w_), oz = cam_.eye.dot(up_w_);
      const double t = dz < 0 && oz > ground_h_ ? (ground_h_ - oz) / dz : -1;
      if (o_.ground_plane && t > 0 && (!hit || t < rh.ray.tfar)) return floor_at(t, dir);
      if (!hit) return bg_lin_;
    }
    return surface_at(static_cast<int>(rh.hit.primID), rh.hit.u, rh.hit.v, dir);
  }

 private:
  // True when the key light is blocked seen from p (offset along n to leave the surface).
  bool in_shadow(const Vector3d& p, const Vector3d& n) const {
    if (!o_.shadows) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray = make_ray(p + 4 * eps_ * n, key_, 0.0f);
    rtcOccluded1(scene_, &ctx, &ray);
    return ray.tfar < 0;
  }
  Vector3d floor_at(double t, const Vector3d& dir) const {
    const Vector3d p = cam_.eye + t * dir;
    const Vector3d horizontal = p - up_w_.dot(p) * up_w_;
    const double fade = std::exp(-horizontal.squaredNorm() / (6.25 * m_.radius * m_.radius));
    const double shadow = key_.dot(up_w_) > 0 && in_shadow(p, up_w_) ? 0.45 : 1.0;
    return bg_lin_ * (1 - fade * (1 - 0.88 * shadow));
  }
  // Face f hit at barycentric (u, v), seen along dir.
  Vector3d surface_at(int f, double u, double v, const Vector3d& dir) const {
    const MatrixX3d& P = m_.P;
    const Vector3d p = (1 - u - v) * P.row(F_(f, 0)) + u * P.row(F_(f, 1)) + v * P.row(F_(f, 2));
    Vector3d ng = NF_.row(f);
    if (ng.squaredNorm() == 0) ng = -dir;
    Vector3d n = (1 - u - v) * CN_.row(3 * f) + u * CN_.row(3 * f + 1) + v * CN_.row(3 * f + 2);
    n = n.squaredNorm() > 1e-12 ? Vector3d(n.normalized()) : ng;
    const double side = ng.dot(dir) > 0 ? -1.0 : 1.0;  // back face: shade the side we see
    ng *= side;
    n *= side;
    const double key_dot = std::max(0.0, n.dot(key_));
    // Shadow rays start from p lifted onto the smooth surface the corner normals describe
    // (Hanika 2021, "Hacking the shadow terminator"), so the facets of a curved surface do not
    // shadow each other near the terminator. Where the true surface faces away from the light
    // the smooth normal fades the light out by itself, so occlusion is tested only where the
    // light can reach the geometry.
    double key_vis = 1;
    if (key_dot > 0 && ng.dot(key_) > 0) {
      Vector3d origin = p;
      const double b[3] = {1 - u - v, u, v};
      for (int k = 0; k < 3; ++k) {
        const Vector3d nk = side * CN_.row(3 * f + k);
        origin -= b[k] * std::min(0.0, (p - P.row(F_(f, k)).transpose()).dot(nk)) * nk;
      }
      key_vis = in_shadow(origin, ng) ? 0.0 : 1.0;
    }
    const double head_dot = std::max(0.0, n.dot(head_));
    const double rim = 0.12 * std::pow(1 - std::max(0.0, n.dot(-dir)), 3);
    const Vector3d& a = albedo_[face_component_[f]];
    return a * (0.05 + 0.85 * key_dot * key_vis + 0.22 * head_dot) + Vector3d::Constant(rim);
  }

  RTCScene scene_;
  const CentredMesh& m_;
  const MatrixX3i& F_;
  const MatrixX3d &NF_, &CN_;
  const std::vector<int>& face_component_;
  const std::vector<Vector3d>& albedo_;
  const Camera& cam_;
  const RenderOptions& o_;
  const Vector3d key_, head_, bg_lin_, up_w_;
  const float eps_;
  double ground_h_ = std::numeric_limits<double>::infinity();
};

// Every pixel the mean of its sub-pixel samples, rows in parallel.
Image trace_image(const Shader& shader, const Camera& cam, const RenderOptions& o) {
  const std::vector<Eigen::Vector2d> pattern = sample_pattern(o.samples_per_pixel);
  Image image;
  image.width = o.width;
  image.height = o.height;
  image.rgb.assign(3 * static_cast<size_t>(o.width) * o.height, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, o.height), [&](const tbb::blocked_range<int>& r) {
    for (int py = r.begin(); py < r.end(); ++py)
      for (int px = 0; px < o.width; ++px) {
        Vector3d sum = Vector3d::Zero();
        for (const Eigen::Vector2d& s : pattern) {
          const double x = (2 * (px + s.x()) / o.width - 1) * cam.tan_half_w;
          const double y = (1 - 2 * (py + s.y()) / o.height) * cam.tan_half_h;
          sum += shader.shade((cam.forward + x * cam.right + y * cam.up).normalized());
        }
        sum /= static_cast<double>(pattern.size());
        unsigned char* out = &image.rgb[3 * (static_cast<size_t>(py) * o.width + px)];
        for (int c = 0; c < 3; ++c) out[c] = linear_to_byte(sum[c]);
      }
  });
  return image;
}

}  // namespace

void RenderOptions::validate() const {
  MQ_CHECK(width >= 16 && width <= 8192 && height >= 16 && height <= 8192, InvalidInput,
           "render: image size ", width, "x", height, " is outside [16, 8192]");
  MQ_CHECK(samples_per_pixel >= 1 && samples_per_pixel <= 64, InvalidInput,
           "render: samples per pixel ", samples_per_pixel, " is outside [1, 64]");
  MQ_CHECK(fov_deg > 0 && fov_deg < 170, InvalidInput, "render: field of view ", fov_deg,
           " degrees is outside (0, 170)");
  MQ_CHECK(elevation_deg > -90 && elevation_deg < 90, InvalidInput, "render: elevation ",
           elevation_deg, " degrees is outside (-90, 90)");
  MQ_CHECK(std::isfinite(azimuth_deg), InvalidInput, "render: azimuth is not finite");
  MQ_CHECK(up_axis >= 0 && up_axis <= 2, InvalidInput, "render: up axis ", up_axis,
           " is not 0, 1 or 2");
}

Image render_mesh(const TriMesh& mesh, const RenderOptions& o) {
  check_mesh(mesh);
  o.validate();
  const MatrixX3i& F = mesh.F;
  const CentredMesh m = centred_mesh(mesh);
  std::vector<int> face_component;
  const int num_components = connected_components(F, mesh.num_vertices(), face_component);
  const std::vector<char> smooth =
      coherently_oriented(F, mesh.num_vertices(), face_component, num_components);
  const MatrixX3d NF = face_normals(m.P, F);
  const MatrixX3d CN = corner_normals(m.P, F, NF, face_component, smooth);
  const std::vector<Vector3d> albedo = element_albedos(num_components, o);
  const EmbreeScene scene = build_scene(m.P, F);
  const Camera cam = frame_camera(m.P, m.referenced, o, m.radius);
  const Shader shader(scene.scene.get(), m, F, NF, CN, face_component, albedo, cam, o);
  return trace_image(shader, cam, o);
}

void write_png(const std::string& path, const Image& image) {
  MQ_CHECK(image.width > 0 && image.height > 0 &&
               image.rgb.size() == 3 * static_cast<size_t>(image.width) * image.height,
           InvalidInput, "write_png: image size ", image.width, "x", image.height,
           " does not match its ", image.rgb.size(), " bytes");
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  // Encoded in memory (first pass sizes the buffer), then written like every other output.
  png_alloc_size_t size = 0;
  std::string bytes;
  int ok = png_image_write_to_memory(&png, nullptr, &size, 0, image.rgb.data(), 3 * image.width,
                                     nullptr);
  if (ok) {
    bytes.resize(size);
    ok = png_image_write_to_memory(&png, bytes.data(), &size, 0, image.rgb.data(), 3 * image.width,
                                   nullptr);
    bytes.resize(size);
  }
  const std::string message = png.message;
  png_image_free(&png);
  if (!ok) MQ_THROW(Error, "cannot encode PNG '", path, "': ", message);
  write_file_atomically(path, bytes);
}

}  // namespace mq
