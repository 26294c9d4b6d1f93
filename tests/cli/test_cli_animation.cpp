// Swatch animation from the command line (issue 25 item 5): `swatch ivy --frames N` writes a
// looping wind, `surface --swatch-frames P --frames A-B` one output per frame, frame 0 the static
// output byte for byte; missing or mismatched frames, and swatches whose method keeps no sources,
// fail in one line before anything is written.
#include <gtest/gtest.h>

#include "core/mesh/mesh_intersections.h"
#include "core/mesh/mesh_io.h"
#include "tests/cli/cli_support.h"

namespace mq {
namespace {

const char* const kIvy = "swatch ivy --count 2 --length 2 --quiet";

TEST(CliAnimation, IvyFramesFollowTheSwatchAndFrameZeroIsTheStaticOutput) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, std::string(kIvy) + " -o sw.obj").status, 0);
  const CliRun frames = meshquilt(dir, std::string(kIvy) + " --frames 6 -o 'sw_%02d.obj'");
  ASSERT_EQ(frames.status, 0) << frames.err;
  const TriMesh swatch = read_mesh(dir + "/sw.obj");
  EXPECT_TRUE(read_mesh(dir + "/sw_00.obj").V == swatch.V);
  EXPECT_FALSE(read_mesh(dir + "/sw_03.obj").V == swatch.V);
  EXPECT_FALSE(fs::exists(dir + "/sw_06.obj"));
  write_mesh(dir + "/base.obj", test::plane_grid(2, 1.5, 20, 15));
  const std::string job = "surface --base base.obj --swatch sw.obj --scale 0.06 --quiet";
  ASSERT_EQ(meshquilt(dir, job + " -o static.ply").status, 0);
  const CliRun run =
      meshquilt(dir, job + " --swatch-frames 'sw_%02d.obj' --frames 0-5 -o 'out_%d.ply'");
  ASSERT_EQ(run.status, 0) << run.err;
  const std::string rest = slurp(dir + "/static.ply");
  EXPECT_TRUE(slurp(dir + "/out_0.ply") == rest);  // not EXPECT_EQ: megabytes
  const TriMesh r = read_mesh(dir + "/static.ply");
  for (int k = 1; k <= 5; ++k) {
    const TriMesh f = read_mesh(dir + "/out_" + std::to_string(k) + ".ply");
    EXPECT_TRUE(f.F == r.F) << k;  // a mesh cache: the same faces in the same order
    EXPECT_TRUE(f.face_kind == r.face_kind) << k;
    EXPECT_TRUE(intersecting_face_pairs(f.V, f.F).empty()) << k;
    if (k == 3) {
      EXPECT_FALSE(f.V == r.V);  // mid-loop the leaves have lifted
    }
  }
}

TEST(CliAnimation, BadFramesAndMethodsAreRefusedBeforeAnyWork) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, std::string(kIvy) + " -o sw.obj").status, 0);
  ASSERT_EQ(meshquilt(dir, std::string(kIvy) + " --frames 3 -o 'sw_%d.obj'").status, 0);
  ASSERT_EQ(meshquilt(dir, "swatch chainmail --rows 3 --cols 3 -o mail.obj --quiet").status, 0);
  // Frame 1 of another mesh: the chain mail.
  fs::copy_file(dir + "/sw_0.obj", dir + "/odd_0.obj");
  fs::copy_file(dir + "/mail.obj", dir + "/odd_1.obj");
  write_mesh(dir + "/base.obj", test::plane_grid(2, 1.5, 20, 15));
  const std::string job = "surface --base base.obj --swatch sw.obj --scale 0.06 --quiet";
  struct Case {
    std::string args;
    int status;
  };
  const Case cases[] = {
      {"--swatch-frames 'sw_%d.obj' --frames 0-5 -o 'x_%d.ply'", 1},   // frames 3-5 missing
      {"--swatch-frames 'odd_%d.obj' --frames 0-1 -o 'x_%d.ply'", 1},  // other connectivity
      {"--swatch-frames 'sw_%d.obj' -o 'x_%d.ply'", 2},                // no --frames
      {"--frames 0-2 -o 'x_%d.ply'", 2},                               // no --swatch-frames
      {"--swatch-frames 'sw_%d.obj' --frames 0-2 -o x.ply", 2},        // -o not a pattern
      {"--swatch-frames 'sw_%d.obj' --frames 0-2 --detail 0.5 -o 'x_%d.ply'", 2},
      {"--swatch-frames 'sw.obj' --frames 0-2 -o 'x_%d.ply'", 2},  // no frame number
  };
  for (const Case& c : cases) {
    const CliRun r = meshquilt(dir, job + " " + c.args);
    EXPECT_EQ(r.status, c.status) << c.args << ": " << r.err;
    EXPECT_EQ(r.err_lines().size(), 1u) << c.args << ": " << r.err;
  }
  // The chain mail's rings keep no sources (the global layout): refused in one line.
  fs::copy_file(dir + "/mail.obj", dir + "/mail_0.obj");
  const CliRun mail =
      meshquilt(dir,
                "surface --base base.obj --swatch mail.obj --scale 0.2 --quiet --swatch-frames "
                "'mail_%d.obj' --frames 0-0 -o 'x_%d.ply'");
  EXPECT_EQ(mail.status, 1) << mail.err;
  EXPECT_EQ(mail.err_lines().size(), 1u) << mail.err;
  for (const char* name : {"x_0.ply", "x_1.ply", "x.ply"})
    EXPECT_FALSE(fs::exists(dir + "/" + name));
  // Only the ivy has a wind.
  EXPECT_EQ(meshquilt(dir, "swatch apples --frames 3 -o 'a_%d.obj' --quiet").status, 2);
}

}  // namespace
}  // namespace mq
