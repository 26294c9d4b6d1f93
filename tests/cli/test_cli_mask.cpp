// surface --element-size (issue 25 item 3): the size in the base's units gives the bytes --scale
// gives for the same size.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "tests/cli/cli_support.h"

namespace mq {
namespace {

// A 10 x 10 grid (exact coordinates) and the 3 x 3 chain mail, written in dir.
void write_inputs(const std::string& dir) {
  ASSERT_EQ(
      meshquilt(dir, "swatch chainmail --rows 3 --cols 3 --detail 16 -o sw.obj --quiet").status, 0);
  write_mesh(dir + "/grid.obj", test::plane_grid(10, 10, 20, 20));
}

TEST(CliSize, ElementSizeGivesTheBytesOfTheSameScale) {
  const std::string dir = test::temp_dir();
  write_inputs(dir);
  const TriMesh grid = read_mesh(dir + "/grid.obj");
  // The size --scale 0.07 gives, in the same arithmetic, printed to round-trip exactly.
  char size[64];
  std::snprintf(size, sizeof size, "%.17g", 0.07 * bounding_box(grid.V, grid.F).extent().norm());
  const std::string job = "surface --base grid.obj --swatch sw.obj --field 1 0 0 --quiet";
  // Same file names (an OBJ names its .mtl), in two folders.
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  ASSERT_EQ(meshquilt(dir, job + " --scale 0.07 -o a/out.obj").status, 0);
  const CliRun b = meshquilt(dir, job + " --element-size " + size + " -o b/out.obj");
  ASSERT_EQ(b.status, 0) << b.err;
  const std::string a_bytes = slurp(dir + "/a/out.obj"), b_bytes = slurp(dir + "/b/out.obj");
  EXPECT_GT(a_bytes.size(), 1000u);
  EXPECT_TRUE(a_bytes == b_bytes);  // not EXPECT_EQ: its diff of megabytes takes gigabytes
  // One of the two; within --scale's range relative to the base.
  for (const std::string bad :
       {" --scale 0.07 --element-size 1", " --element-size 0", " --element-size 1e-9",
        " --element-size 1e3", " --element-size nan"}) {
    const CliRun r = meshquilt(dir, job + bad + " -o c.obj");
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/c.obj"));
}

}  // namespace
}  // namespace mq
