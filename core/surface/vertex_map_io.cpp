#include "core/surface/vertex_map_io.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/input_file.h"

namespace mq {

namespace {

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

// Calls visit(line number, trimmed text) for each line of `text` that is neither empty nor a
// '#' comment, in order.
template <typename Visit>
void for_each_value_line(const std::string& text, Visit visit) {
  int line = 0;
  for (std::size_t at = 0; at <= text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string s = trimmed(text.substr(at, end - at));
    at = end + 1;
    ++line;
    if (s.empty() || s[0] == '#') continue;
    visit(line, s);
  }
}

}  // namespace

SurfaceMask parse_surface_mask(const std::string& text, const std::string& name,
                               const TriMesh& base) {
  SurfaceMask mask;
  std::vector<double> weights;
  bool faces = false, first = true, any = false;
  for_each_value_line(text, [&](int line, const std::string& s) {
    if (first && s == "faces") {
      faces = true;
      first = false;
      mask.face.assign(static_cast<size_t>(base.num_faces()), 0);
      return;
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
  });
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
  for_each_value_line(text, [&](int line, const std::string& s) {
    char* stop = nullptr;
    const double size = std::strtod(s.c_str(), &stop);
    MQ_CHECK(stop == s.c_str() + s.size() && std::isfinite(size) && size > 0, InvalidInput, name,
             ":", line, ": expected a positive element size factor, got '", s, "'");
    MQ_CHECK(static_cast<int>(sizes.size()) < base.num_vertices(), InvalidInput, name, ":", line,
             ": more sizes than the base's ", base.num_vertices(), " vertices");
    sizes.push_back(size);
  });
  MQ_CHECK(static_cast<int>(sizes.size()) == base.num_vertices(), InvalidInput, name, ": ",
           sizes.size(), " sizes for the base's ", base.num_vertices(), " vertices");
  return Eigen::Map<const Eigen::VectorXd>(sizes.data(), static_cast<Eigen::Index>(sizes.size()));
}

Eigen::VectorXd read_size_map(const std::string& path, const TriMesh& base) {
  return parse_size_map(read_input_file(path, "size map", std::size_t{1} << 30), path, base);
}

}  // namespace mq
