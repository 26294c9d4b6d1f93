// Swatch animation from the command line (issue 25 item 5): `swatch ivy --frames N` writes a
// looping wind, `surface --swatch-frames P --frames A-B` one output per frame, frame 0 the static
// output byte for byte; chain mail (the global layout's lattice), the weave by the local patches
// (threads cut and stitched) and by the global layout, and `plane`'s layer follow their swatch's
// frames too; missing or mismatched
// frames fail in one line before anything is written.
#include <gtest/gtest.h>

#include <cmath>

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

// The global layout's lattice keeps its sources (each ring a copy of its swatch ring), so chain
// mail follows a swatch frame that lifts the whole layer by a fifth of its thickness and shifts it
// by a twentieth: on a plane every vertex by one vector, of that length at the output's scale; on
// an open cylinder along the surface's own normal there; nothing meets in either.
TEST(CliAnimation, ChainMailFollowsALiftedLayer) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, "swatch chainmail --rows 4 --cols 4 -o mail.obj --quiet").status, 0);
  TriMesh lifted = read_mesh(dir + "/mail.obj");
  const double H = lifted.V.col(2).maxCoeff() - lifted.V.col(2).minCoeff();
  lifted.V.col(0).array() += 0.05 * H;
  lifted.V.col(2).array() += 0.2 * H;
  write_mesh(dir + "/mail_1.obj", lifted);
  fs::copy_file(dir + "/mail.obj", dir + "/mail_0.obj");
  const double lift = std::hypot(0.05, 0.2);  // of the layer's thickness
  write_mesh(dir + "/plane.obj", test::plane_grid(2, 1.5, 20, 15));
  write_mesh(dir + "/tube.obj", test::open_cylinder(0.5, 2, 48, 24));
  for (const std::string base : {"plane", "tube"}) {
    SCOPED_TRACE(base);
    const CliRun run =
        meshquilt(dir, "surface --base " + base + ".obj --swatch mail.obj --scale " +
                           (base == "plane" ? "0.3" : "0.25") +
                           " --swatch-frames 'mail_%d.obj' --frames 0-1 -o '" + base + "_%d.obj'");
    ASSERT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.out.find("0 elements move at half their motion and 0 stay still"),
              std::string::npos)
        << run.out;
    const TriMesh rest = read_mesh(dir + "/" + base + "_0.obj"),
                  moved = read_mesh(dir + "/" + base + "_1.obj");
    ASSERT_TRUE(moved.F == rest.F);
    ASSERT_GT(rest.num_vertices(), 10'000);
    const double shell = std::stod(run.out.substr(run.out.find("shell height ") + 13));
    const MatrixX3d d = moved.V - rest.V;
    int along_normal = 0;
    for (int v = 0; v < rest.num_vertices(); ++v) {
      // Within the printed shell height's 4 digits; the OBJ's 9 digits for one vector.
      ASSERT_NEAR(d.row(v).norm(), lift * shell, 1e-3 * shell) << v;
      if (base == "plane") {
        ASSERT_LT((d.row(v) - d.row(0)).norm(), 1e-6 * shell) << v;
        continue;
      }
      // The tube's normal at the vertex: radial, away from its axis (z).
      const Vector3d radial = Vector3d(rest.V(v, 0), rest.V(v, 1), 0).normalized();
      along_normal += d.row(v).dot(radial) > 0.9 * 0.2 * shell;
    }
    if (base == "plane") {
      EXPECT_NEAR(d(0, 2), 0.2 * shell, 1e-3 * shell);
    } else {
      EXPECT_GT(along_normal, 0.95 * rest.num_vertices());
    }
    EXPECT_TRUE(intersecting_face_pairs(moved.V, moved.F).empty());
  }
}

// The weave, by the local patches (threads cut and stitched where patches meet) and by the global
// layout (one-period pieces welded into threads), follows a swatch frame that lifts the layer by a
// fifth of its thickness: frame 0 is the static output byte for byte (keeping the sources changes
// nothing), and in frame 1 every vertex moves by the lift at the output's scale along the plane's
// normal; nothing meets.
class CliWeaveAnimation : public ::testing::TestWithParam<const char*> {};

TEST_P(CliWeaveAnimation, ThreadsFollowALiftedLayer) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, "swatch weave --rows 4 --cols 4 --detail 8 -o w.obj --quiet").status, 0);
  TriMesh lifted = read_mesh(dir + "/w.obj");
  const double H = lifted.V.col(2).maxCoeff() - lifted.V.col(2).minCoeff();
  lifted.V.col(2).array() += 0.2 * H;
  write_mesh(dir + "/w_1.obj", lifted);
  fs::copy_file(dir + "/w.obj", dir + "/w_0.obj");
  write_mesh(dir + "/plane.obj", test::plane_grid(2, 1.5, 20, 15));
  const std::string method = GetParam();
  const std::string job =
      "surface --base plane.obj --swatch w.obj --scale 0.2 --method " + method + " --stats s.json";
  const CliRun still = meshquilt(dir, job + " -o static.ply");
  ASSERT_EQ(still.status, 0) << still.err;
  const CliRun run =
      meshquilt(dir, job + " --swatch-frames 'w_%d.obj' --frames 0-1 -o 'out_%d.ply'");
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_TRUE(slurp(dir + "/out_0.ply") == slurp(dir + "/static.ply"));
  const std::string stats = slurp(dir + "/s.json");
  const std::string count = method == "patches" ? "\"stitched\": " : "\"thread_welds\": ";
  const size_t at = stats.find(count);
  ASSERT_NE(at, std::string::npos);
  EXPECT_GT(std::stoi(stats.substr(at + count.size())), 0);  // threads cut and stitched, welded
  const TriMesh rest = read_mesh(dir + "/out_0.ply"), moved = read_mesh(dir + "/out_1.ply");
  ASSERT_TRUE(moved.F == rest.F);
  const double shell = std::stod(run.out.substr(run.out.find("shell height ") + 13));
  const MatrixX3d d = moved.V - rest.V;
  for (int v = 0; v < rest.num_vertices(); ++v) {
    ASSERT_NEAR(d.row(v).norm(), 0.2 * shell, 0.01 * shell) << v;
    ASSERT_GT(d(v, 2), 0.9999 * d.row(v).norm()) << v;
  }
  EXPECT_TRUE(intersecting_face_pairs(moved.V, moved.F).empty());
}

INSTANTIATE_TEST_SUITE_P(PatchesAndGlobal, CliWeaveAnimation,
                         ::testing::Values("patches", "global"));

// `plane` follows swatch frames too: the weave's layer, its threads stitched where patches meet,
// lifted by a fifth of the swatch's thickness moves every vertex by that lift, frame 0 being the
// static layer byte for byte; a frame range without frames is a usage error.
TEST(CliAnimation, PlaneLayerFollowsALiftedSwatch) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, "swatch weave --rows 4 --cols 4 --detail 8 -o w.obj --quiet").status, 0);
  TriMesh lifted = read_mesh(dir + "/w.obj");
  const double lift = 0.2 * (lifted.V.col(2).maxCoeff() - lifted.V.col(2).minCoeff());
  lifted.V.col(2).array() += lift;
  write_mesh(dir + "/w_1.obj", lifted);
  fs::copy_file(dir + "/w.obj", dir + "/w_0.obj");
  const std::string job = "plane --swatch w.obj --size 8 6 --quiet --stats s.json";
  ASSERT_EQ(meshquilt(dir, job + " -o static.ply").status, 0);
  const CliRun run =
      meshquilt(dir, job + " --swatch-frames 'w_%d.obj' --frames 0-1 -o 'out_%d.ply'");
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_TRUE(slurp(dir + "/out_0.ply") == slurp(dir + "/static.ply"));
  const std::string stats = slurp(dir + "/s.json");
  const size_t at = stats.find("\"stitched\": ");
  ASSERT_NE(at, std::string::npos);
  EXPECT_GT(std::stoi(stats.substr(at + 12)), 0);
  const TriMesh rest = read_mesh(dir + "/out_0.ply"), moved = read_mesh(dir + "/out_1.ply");
  ASSERT_TRUE(moved.F == rest.F);
  for (int v = 0; v < rest.num_vertices(); ++v)
    ASSERT_LT((moved.V.row(v) - rest.V.row(v) - Vector3d(0, 0, lift).transpose()).norm(),
              1e-5 * lift)
        << v;
  const CliRun lone = meshquilt(dir, job + " --frames 0-1 -o 'x_%d.ply'");
  EXPECT_EQ(lone.status, 2) << lone.err;
  EXPECT_EQ(lone.err_lines().size(), 1u) << lone.err;
}

TEST(CliAnimation, BadFramesAreRefusedBeforeAnyWork) {
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
  for (const char* name : {"x_0.ply", "x_1.ply", "x.ply"})
    EXPECT_FALSE(fs::exists(dir + "/" + name));
  // Only the ivy has a wind.
  EXPECT_EQ(meshquilt(dir, "swatch apples --frames 3 -o 'a_%d.obj' --quiet").status, 2);
}

}  // namespace
}  // namespace mq
