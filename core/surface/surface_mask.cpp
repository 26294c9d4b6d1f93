#include "core/surface/surface_mask.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/input_file.h"

namespace mq {

namespace {

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

}  // namespace

bool SurfaceMask::contains(const TriMesh& base, int f, const Vector3d& b) const {
  if (!face.empty()) return face[static_cast<size_t>(f)] != 0;
  double w = 0;
  for (int k = 0; k < 3; ++k) w += b(k) * vertex_weight(base.F(f, k));
  return w >= 0.5;
}

SurfaceMask parse_surface_mask(const std::string& text, const std::string& name,
                               const TriMesh& base) {
  SurfaceMask mask;
  std::vector<double> weights;
  bool faces = false, first = true, any = false;
  int line = 0;
  for (std::size_t at = 0; at <= text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string s = trimmed(text.substr(at, end - at));
    at = end + 1;
    ++line;
    if (s.empty() || s[0] == '#') continue;
    if (first && s == "faces") {
      faces = true;
      first = false;
      mask.face.assign(static_cast<size_t>(base.num_faces()), 0);
      continue;
    }
    first = false;
    errno = 0;
    char* stop = nullptr;
    if (faces) {
      const long f = std::strtol(s.c_str(), &stop, 10);
      MQ_CHECK(stop == s.c_str() + s.size() && errno == 0, InvalidInput, name, ":", line,
               ": expected a face index, got '", s, "'");
      MQ_CHECK(f >= 0 && f < base.num_faces(), InvalidInput, name, ":", line, ": face ", f,
               " out of range (the base has ", base.num_faces(), " faces)");
      mask.face[static_cast<size_t>(f)] = 1;
      any = true;
    } else {
      const double w = std::strtod(s.c_str(), &stop);
      MQ_CHECK(stop == s.c_str() + s.size() && w >= 0 && w <= 1, InvalidInput, name, ":", line,
               ": expected a weight in [0, 1], got '", s, "'");
      MQ_CHECK(static_cast<int>(weights.size()) < base.num_vertices(), InvalidInput, name, ":",
               line, ": more weights than the base's ", base.num_vertices(), " vertices");
      weights.push_back(w);
      any = any || w >= 0.5;
    }
  }
  if (!faces) {
    MQ_CHECK(static_cast<int>(weights.size()) == base.num_vertices(), InvalidInput, name, ": ",
             weights.size(), " weights for the base's ", base.num_vertices(),
             " vertices (or a first line 'faces' for a list of face indices)");
    mask.vertex_weight = Eigen::Map<const Eigen::VectorXd>(
        weights.data(), static_cast<Eigen::Index>(weights.size()));
  }
  MQ_CHECK(any, InvalidInput, name, ": the mask is empty (",
           faces ? "no face listed" : "no weight >= 0.5", "): nothing to quilt");
  return mask;
}

SurfaceMask read_surface_mask(const std::string& path, const TriMesh& base) {
  return parse_surface_mask(read_input_file(path, "mask file", std::size_t{1} << 30), path, base);
}

Eigen::VectorXd parse_size_map(const std::string& text, const std::string& name,
                               const TriMesh& base) {
  std::vector<double> sizes;
  int line = 0;
  for (std::size_t at = 0; at <= text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string s = trimmed(text.substr(at, end - at));
    at = end + 1;
    ++line;
    if (s.empty() || s[0] == '#') continue;
    char* stop = nullptr;
    const double size = std::strtod(s.c_str(), &stop);
    MQ_CHECK(stop == s.c_str() + s.size() && std::isfinite(size) && size > 0, InvalidInput, name,
             ":", line, ": expected a positive element size factor, got '", s, "'");
    MQ_CHECK(static_cast<int>(sizes.size()) < base.num_vertices(), InvalidInput, name, ":", line,
             ": more sizes than the base's ", base.num_vertices(), " vertices");
    sizes.push_back(size);
  }
  MQ_CHECK(static_cast<int>(sizes.size()) == base.num_vertices(), InvalidInput, name, ": ",
           sizes.size(), " sizes for the base's ", base.num_vertices(), " vertices");
  return Eigen::Map<const Eigen::VectorXd>(sizes.data(), static_cast<Eigen::Index>(sizes.size()));
}

Eigen::VectorXd read_size_map(const std::string& path, const TriMesh& base) {
  return parse_size_map(read_input_file(path, "size map", std::size_t{1} << 30), path, base);
}

double masked_area_share(const SurfaceMask& mask, const TriMesh& base) {
  const Eigen::VectorXd area = face_areas(base.V, base.F);
  const Vector3d samples[4] = {Vector3d::Constant(1.0 / 3), Vector3d(2.0 / 3, 1.0 / 6, 1.0 / 6),
                               Vector3d(1.0 / 6, 2.0 / 3, 1.0 / 6),
                               Vector3d(1.0 / 6, 1.0 / 6, 2.0 / 3)};
  double in = 0;
  for (int f = 0; f < base.num_faces(); ++f)
    for (const Vector3d& b : samples) in += 0.25 * area(f) * (mask.contains(base, f, b) ? 1 : 0);
  const double total = area.sum();
  return total > 0 ? std::clamp(in / total, 0.0, 1.0) : 0.0;
}

std::vector<char> mask_quilt_faces(const SurfaceMask& mask, const TriMesh& base,
                                   const SurfaceQuilt& quilt) {
  MQ_CHECK(mask.face.empty() ? mask.vertex_weight.size() == base.num_vertices()
                             : static_cast<int>(mask.face.size()) == base.num_faces(),
           InvalidInput, "the mask does not fit the base (", base.num_vertices(), " vertices, ",
           base.num_faces(), " faces)");
  const TriMesh& refined = quilt.base;
  MatrixX3d centroids(refined.num_faces(), 3);
  for (int f = 0; f < refined.num_faces(); ++f)
    centroids.row(f) = (refined.V.row(refined.F(f, 0)) + refined.V.row(refined.F(f, 1)) +
                        refined.V.row(refined.F(f, 2))) /
                       3.0;
  const ClosestPointQuery query(base.V, base.F);
  const std::vector<ClosestPointHit> hits = query.closest(centroids);
  std::vector<char> out(static_cast<size_t>(refined.num_faces()), 0);
  for (int f = 0; f < refined.num_faces(); ++f) {
    const ClosestPointHit& h = hits[static_cast<size_t>(f)];
    out[static_cast<size_t>(f)] = h.face >= 0 && mask.contains(base, h.face, h.barycentric);
  }
  return out;
}

int drop_unmasked_elements(SurfaceQuilt& quilt, const std::vector<char>& faces) {
  MQ_CHECK(static_cast<int>(faces.size()) == quilt.base.num_faces(), InvalidInput, "the mask has ",
           faces.size(), " faces for the quilt's ", quilt.base.num_faces());
  const std::size_t before = quilt.elements.size();
  auto& elements = quilt.elements;
  elements.erase(std::remove_if(elements.begin(), elements.end(),
                                [&](const SurfaceElement& e) {
                                  std::size_t inside = 0;
                                  for (const int f : e.face)
                                    inside += faces[static_cast<size_t>(f)] != 0;
                                  return 2 * inside < e.face.size();
                                }),
                 elements.end());
  return static_cast<int>(before - quilt.elements.size());
}

}  // namespace mq
