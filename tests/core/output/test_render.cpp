#include <gtest/gtest.h>
#include <png.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>

#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/output/render.h"
#include "tests/test_support.h"

namespace mq {
namespace {

RenderOptions small_options() {
  RenderOptions o;
  o.width = 96;
  o.height = 72;
  o.samples_per_pixel = 2;
  return o;
}

std::array<int, 3> pixel(const Image& im, int x, int y) {
  const unsigned char* p = &im.rgb[3 * (static_cast<size_t>(y) * im.width + x)];
  return {p[0], p[1], p[2]};
}

bool is_background(const Image& im, int x, int y, const RenderOptions& o) {
  const auto p = pixel(im, x, y);
  return p[0] == o.background[0] && p[1] == o.background[1] && p[2] == o.background[2];
}

// Fraction of the image width/height spanned by non-background pixels.
std::pair<double, double> object_extent(const Image& im, const RenderOptions& o) {
  int xmin = im.width, xmax = -1, ymin = im.height, ymax = -1;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      if (!is_background(im, x, y, o)) {
        xmin = std::min(xmin, x), xmax = std::max(xmax, x);
        ymin = std::min(ymin, y), ymax = std::max(ymax, y);
      }
  if (xmax < 0) return {0, 0};
  return {double(xmax - xmin + 1) / im.width, double(ymax - ymin + 1) / im.height};
}

void expect_framed(const Image& im, const RenderOptions& o) {
  ASSERT_EQ(im.width, o.width);
  ASSERT_EQ(im.height, o.height);
  ASSERT_EQ(im.rgb.size(), size_t(3) * o.width * o.height);
  for (int x : {0, o.width - 1})
    for (int y : {0, o.height - 1}) EXPECT_TRUE(is_background(im, x, y, o)) << x << "," << y;
  // The object fills about 80% of the tighter dimension and never touches the border.
  const auto [fx, fy] = object_extent(im, o);
  EXPECT_GT(std::max(fx, fy), 0.7);
  EXPECT_LT(fx, 0.9);
  EXPECT_LT(fy, 0.9);
}

TEST(Render, UnitCubeFramedAndShaded) {
  const RenderOptions o = small_options();
  const Image im = render_mesh(test::unit_cube(), o);
  expect_framed(im, o);
  EXPECT_FALSE(is_background(im, o.width / 2, o.height / 2, o));
  // Three visible faces of a cube under directional light: at least three distinct shades.
  std::set<std::array<int, 3>> shades;
  for (int y = o.height / 4; y < 3 * o.height / 4; ++y)
    for (int x = o.width / 4; x < 3 * o.width / 4; ++x)
      if (!is_background(im, x, y, o)) shades.insert(pixel(im, x, y));
  EXPECT_GE(shades.size(), 3u);
}

TEST(Render, TorusHasHoleInTheMiddleSeenFromAbove) {
  RenderOptions o = small_options();
  o.up_axis = 2;  // the fixture's axis is z
  o.elevation_deg = 89;
  o.ground_plane = false;
  const Image im = render_mesh(test::torus(1.0, 0.3, 48, 16), o);
  expect_framed(im, o);
  EXPECT_TRUE(is_background(im, o.width / 2, o.height / 2, o));                       // the hole
  EXPECT_FALSE(is_background(im, o.width / 2, o.height / 2 + o.height * 3 / 10, o));  // the ring
}

TEST(Render, InvertedMeshLooksTheSame) {
  // Two-sided shading: flipping every face must not darken the object.
  const RenderOptions o = small_options();
  TriMesh cube = test::unit_cube();
  const Image a = render_mesh(cube, o);
  cube.F.col(1).swap(cube.F.col(2));
  const Image b = render_mesh(cube, o);
  long diff = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) diff += std::abs(int(a.rgb[i]) - int(b.rgb[i]));
  EXPECT_LT(double(diff) / a.rgb.size(), 1.0);
}

TEST(Render, ComponentsGetDifferentColours) {
  RenderOptions o = small_options();
  o.azimuth_deg = 0;
  o.elevation_deg = 0;
  o.shadows = false;
  TriMesh two = test::unit_cube();
  TriMesh right = test::unit_cube();
  right.V.col(0).array() += 1.5;
  append_mesh(two, right);
  const Image im = render_mesh(two, o);
  // Looking down -z at the two front faces: left cube at x<0.5, right cube at x>0.5 of the view.
  const auto left_px = pixel(im, o.width * 3 / 10, o.height / 2);
  const auto right_px = pixel(im, o.width * 7 / 10, o.height / 2);
  EXPECT_FALSE(is_background(im, o.width * 3 / 10, o.height / 2, o));
  EXPECT_FALSE(is_background(im, o.width * 7 / 10, o.height / 2, o));
  int d = 0;
  for (int c = 0; c < 3; ++c) d += std::abs(left_px[c] - right_px[c]);
  EXPECT_GT(d, 40);

  o.color_elements = false;  // same lighting, same colour
  const Image gray = render_mesh(two, o);
  const auto l = pixel(gray, o.width * 3 / 10, o.height / 2);
  const auto r = pixel(gray, o.width * 7 / 10, o.height / 2);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[c], r[c], 2);
}

TEST(Render, DeterministicAcrossRunsAndThreadCounts) {
  RenderOptions o = small_options();
  o.ground_plane = true;
  const TriMesh torus = test::torus(1.0, 0.3, 40, 12);
  Image one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = render_mesh(torus, o);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = render_mesh(torus, o);
  }
  const Image again = render_mesh(torus, o);
  EXPECT_EQ(one.rgb, two.rgb);
  EXPECT_EQ(one.rgb, again.rgb);
}

TEST(Render, ShadowsAndGroundPlaneChangeTheImage) {
  RenderOptions o = small_options();
  TriMesh two = test::unit_cube();
  TriMesh top = test::unit_cube();
  top.V.col(1).array() += 1.2;  // a second cube above the first: it shadows the lower one
  top.V.col(0).array() -= 0.6;
  append_mesh(two, top);
  o.shadows = false;
  const Image flat = render_mesh(two, o);
  o.shadows = true;
  const Image shadowed = render_mesh(two, o);
  EXPECT_NE(flat.rgb, shadowed.rgb);
  long darker = 0;
  for (size_t i = 0; i < flat.rgb.size(); ++i) darker += flat.rgb[i] > shadowed.rgb[i];
  EXPECT_GT(darker, 30);
  o.ground_plane = true;
  const Image ground = render_mesh(two, o);
  // The floor darkens pixels that were background below the object.
  EXPECT_NE(ground.rgb, shadowed.rgb);
}

TEST(Render, WritePngRoundTrip) {
  const RenderOptions o = small_options();
  const Image im = render_mesh(test::torus(1.0, 0.3, 32, 12), o);
  const std::string dir = test::temp_dir();
  const std::string path = dir + "/torus.png";
  write_png(path, im);
  ASSERT_TRUE(std::filesystem::exists(path));

  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&png, path.c_str())) << png.message;
  EXPECT_EQ(int(png.width), o.width);
  EXPECT_EQ(int(png.height), o.height);
  png.format = PNG_FORMAT_RGB;
  std::vector<unsigned char> back(PNG_IMAGE_SIZE(png));
  ASSERT_TRUE(png_image_finish_read(&png, nullptr, back.data(), 0, nullptr)) << png.message;
  EXPECT_EQ(back, im.rgb);

  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    files += entry.is_regular_file();
  EXPECT_EQ(files, 1);  // no temporary file left behind
}

TEST(Render, WritePngFailureNamesTheFile) {
  Image im;
  im.width = im.height = 16;
  im.rgb.assign(3 * 16 * 16, 100);
  const std::string path = test::temp_dir() + "/no/such/dir/out.png";
  try {
    write_png(path, im);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  im.rgb.pop_back();
  EXPECT_THROW(write_png(path + ".bad.png", im), InvalidInput);
}

TEST(Render, InvalidInputThrows) {
  EXPECT_THROW(render_mesh(TriMesh{}), InvalidInput);
  TriMesh nan = test::unit_cube();
  nan.V(3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(render_mesh(nan, small_options()), InvalidInput);
  TriMesh bad_index = test::unit_cube();
  bad_index.F(2, 0) = 8;
  EXPECT_THROW(render_mesh(bad_index, small_options()), InvalidInput);
  RenderOptions o = small_options();
  o.width = 15;
  EXPECT_THROW(render_mesh(test::unit_cube(), o), InvalidInput);
  o = small_options();
  o.height = 8193;
  EXPECT_THROW(render_mesh(test::unit_cube(), o), InvalidInput);
  o = small_options();
  o.samples_per_pixel = 0;
  EXPECT_THROW(render_mesh(test::unit_cube(), o), InvalidInput);
  o = small_options();
  o.fov_deg = 0;
  EXPECT_THROW(render_mesh(test::unit_cube(), o), InvalidInput);
}

TEST(Render, RealMeshBunny) {
  RenderOptions o = small_options();
  o.width = 128;
  o.height = 96;
  const Image im = render_mesh(read_mesh(test::shared_data("base/bunny_igl_7k.off")), o);
  expect_framed(im, o);
  EXPECT_FALSE(is_background(im, o.width / 2, o.height / 2, o));
}

TEST(Render, OptionsValidate) {
  RenderOptions o;
  EXPECT_NO_THROW(o.validate());
  o.up_axis = 3;
  EXPECT_THROW(o.validate(), InvalidInput);
  o.up_axis = 1;
  o.fov_deg = 0;
  EXPECT_THROW(o.validate(), InvalidInput);
}

}  // namespace
}  // namespace mq
