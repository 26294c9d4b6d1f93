// Preview renderer: ray casts a triangle mesh (Embree) into an RGB image and writes it as PNG.
// Meant for showing results (`meshquilt render`), not for photorealism.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

struct RenderOptions {
  int width = 1024;  // pixels, in [16, 8192]
  int height = 768;  // pixels, in [16, 8192]
  // Camera orbit around the bounding-box centre: azimuth about the up axis, elevation above
  // the plane orthogonal to it. The distance is chosen so the object fills ~80% of the image.
  double azimuth_deg = 35;
  double elevation_deg = 30;  // in (-90, 90)
  double fov_deg = 35;        // vertical field of view, in (0, 170)
  int up_axis = 1;            // world up: 0 = x, 1 = y, 2 = z
  // Each connected component (geometry element) gets its own hue from a fixed sequence indexed
  // by the component id; otherwise everything is a neutral clay colour.
  bool color_elements = true;
  // When not empty: the colour (sRGB) of each connected component in order, overriding the
  // hue sequence (e.g. elements coloured by a figure such as their link count).
  std::vector<std::array<unsigned char, 3>> element_colors;
  // Components from this index on (in connected_components order) are drawn in the neutral clay
  // colour whatever the colouring: a base surface appended after the texture (-1: none).
  int neutral_from = -1;
  std::array<unsigned char, 3> background{{245, 245, 245}};
  int samples_per_pixel = 4;  // fixed sub-pixel pattern, in [1, 64]
  bool shadows = true;        // hard shadows from the key light
  bool ground_plane = false;  // shadow-catching floor under the object

  // Throws InvalidInput for a size, sample count, angle or axis outside its range (above).
  void validate() const;
};

// An 8-bit RGB image, rows top to bottom, rgb.size() == 3 * width * height.
struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

// Renders the mesh with a headlight and a key light: Lambert shading plus a little ambient and
// a soft rim term, hard shadows from the key light, two-sided (back faces use the flipped
// normal, so inverted meshes look right). Elements whose faces are coherently oriented are
// smooth shaded with area-weighted normals that do not average across creases sharper than
// 75 degrees; other elements are flat shaded. Rows are rendered in parallel (TBB); the bytes
// are identical whatever the thread count.
//   mesh  V #V by 3, F #F by 3 (N is ignored)
// Throws InvalidInput for an empty mesh, a non-finite coordinate, an out-of-range index, an
// option outside its documented range (options.validate()) or element_colors of the wrong size;
// InternalError if Embree cannot be initialised.
Image render_mesh(const TriMesh& mesh, const RenderOptions& options = {});

// Writes an 8-bit RGB PNG atomically: to a temporary file beside path, then renamed over it.
// Throws InvalidInput if image's size does not match its pixels; Error naming the file on any
// I/O failure (the temporary file is removed).
void write_png(const std::string& path, const Image& image);

}  // namespace mq
