// The meshquilt executable, run as a user would: help, errors, every subcommand end to end,
// and byte-identical output whatever the thread count or device.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/huge_pages.h"
#include "tests/cli/cli_support.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// A small chain mail swatch (9 rings) written by the CLI itself.
std::string small_swatch(const std::string& dir) {
  const CliRun r =
      meshquilt(dir, "swatch chainmail --rows 3 --cols 3 --detail 24 -o sw.obj --quiet");
  EXPECT_EQ(r.status, 0) << r.err;
  return "sw.obj";
}

bool opencl_platform_present() {
  FILE* p = popen("clinfo -l 2>/dev/null", "r");
  if (!p) return false;
  std::string text;
  char buf[256];
  while (std::fgets(buf, sizeof buf, p)) text += buf;
  pclose(p);
  return text.find("Platform #") != std::string::npos;
}

TEST(Cli, HelpOfEveryCommand) {
  const std::string dir = test::temp_dir();
  for (const std::string cmd : {"", "plane", "surface", "swatch", "info", "render"}) {
    const CliRun r = meshquilt(dir, cmd + " --help");
    EXPECT_EQ(r.status, 0) << cmd;
    EXPECT_NE(r.out.find("usage: meshquilt " + cmd), std::string::npos) << cmd << ":\n" << r.out;
    EXPECT_TRUE(r.err.empty()) << cmd << ": " << r.err;
    // The exit statuses, which a farm scheduler's retry rule needs (issue 24).
    for (const char* status :
         {"exit status: 0 done; 1 bad input", "2 bad usage", "3 internal error"})
      EXPECT_NE(r.out.find(status), std::string::npos) << cmd << " --help lacks '" << status << "'";
  }
  const CliRun v = meshquilt(dir, "--version");
  EXPECT_EQ(v.status, 0);
  EXPECT_EQ(v.out.rfind("meshquilt ", 0), 0u);
}

TEST(Cli, UnknownCommandOrOptionExitsTwoWithOneLine) {
  const std::string dir = test::temp_dir();
  for (const std::string args :
       {"frobnicate", "plane --bogus", "swatch chainmail -o x.obj --bogus 3", "info --nope x.obj",
        "render x.obj -o x.png --zoom 2", "swatch teapot -o x.obj", "plane --swatch"}) {
    const CliRun r = meshquilt(dir, args);
    EXPECT_EQ(r.status, 2) << args;
    const auto lines = r.err_lines();
    ASSERT_EQ(lines.size(), 1u) << args << ":\n" << r.err;
    EXPECT_EQ(lines[0].rfind("meshquilt", 0), 0u) << lines[0];
    EXPECT_TRUE(r.out.empty()) << args;
  }
  EXPECT_TRUE(listing(dir).empty());
}

TEST(Cli, SwatchKindsAreClosed) {
  const std::string dir = test::temp_dir();
  for (const std::string kind : {"chainmail", "weave", "apples", "ivy"}) {
    const std::string small =
        kind == "chainmail" || kind == "weave" ? " --rows 2 --cols 3 --detail 8" : " --count 4";
    const CliRun s = meshquilt(dir, "swatch " + kind + small + " -o " + kind + ".off");
    ASSERT_EQ(s.status, 0) << kind << ": " << s.err;
    ASSERT_TRUE(fs::exists(dir + "/" + kind + ".off"));
    const CliRun i = meshquilt(dir, "info " + kind + ".off --json");
    ASSERT_EQ(i.status, 0) << i.err;
    EXPECT_EQ(json_value(i.out, "closed"), "true") << kind << "\n" << i.out;
    EXPECT_EQ(json_value(i.out, "boundary_edges"), "0") << kind;
    EXPECT_NE(json_value(i.out, "elements"), "1") << kind;
  }
  // info --intersections on a generated swatch: its elements do not intersect.
  const CliRun i = meshquilt(dir, "info chainmail.off --json --intersections");
  ASSERT_EQ(i.status, 0) << i.err;
  EXPECT_NE(i.out.find("intersect"), std::string::npos) << i.out;
}

TEST(Cli, PlaneEndToEndWithStats) {
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  const CliRun r =
      meshquilt(dir, "plane --swatch " + sw + " --size 8 7 -o out.ply --stats s.json --device cpu");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote out.ply"), std::string::npos) << r.out;
  ASSERT_TRUE(fs::exists(dir + "/out.ply"));
  const std::string stats = slurp(dir + "/s.json");
  for (const char* key : {"iterations", "faces", "vertices", "elements", "stitched", "replaced",
                          "added", "removed_post", "stage_seconds", "matching", "merging"})
    EXPECT_NE(stats.find("\"" + std::string(key) + "\":"), std::string::npos) << key;
  EXPECT_GT(std::stoi(json_value(stats, "iterations")), 1);
  // The run's own check of its structure (issue 23): nothing short on a chain mail layer.
  EXPECT_EQ(json_value(stats, "passed"), "true");
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  // The counts agree with what info reads back from the file.
  const CliRun i = meshquilt(dir, "info out.ply --json");
  ASSERT_EQ(i.status, 0) << i.err;
  const size_t output = stats.find("\"output\":");
  ASSERT_NE(output, std::string::npos);
  EXPECT_EQ(json_value(stats.substr(output), "faces"), json_value(i.out, "faces"));
  EXPECT_EQ(json_value(stats.substr(output), "vertices"), json_value(i.out, "vertices"));
  EXPECT_EQ(json_value(stats.substr(output), "elements"), json_value(i.out, "elements"));
  EXPECT_EQ(json_value(i.out, "closed"), "true");
  // No temporary files left beside the outputs.
  const std::vector<std::string> expected{"out.ply", "s.json", "sw.mtl", "sw.obj"};
  EXPECT_EQ(listing(dir), expected);
}

// Each bad invocation exits non-zero without a crash, prints one line starting with "meshquilt",
// and leaves no output file behind; an existing output file is left untouched.
TEST(Cli, BadInputFailsCleanly) {
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  spit(dir + "/empty.obj", "");
  spit(dir + "/truncated.off", "OFF\n8 12 0\n0 0 0\n1 0 0\n0 1 0\n");
  spit(dir + "/nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
  spit(dir + "/garbage.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
  struct Case {
    std::string args, out;
  };
  const std::vector<Case> cases{
      {"plane --swatch missing.obj --size 5 5 -o o.obj", "o.obj"},
      {"plane --swatch empty.obj --size 5 5 -o o.obj", "o.obj"},
      {"plane --swatch truncated.off --size 5 5 -o o.obj", "o.obj"},
      {"plane --swatch nan.off --size 5 5 -o o.obj", "o.obj"},
      {"plane --swatch garbage.obj --size 5 5 -o o.obj", "o.obj"},
      {"plane --swatch " + sw + " --size 0 5 -o o.obj", "o.obj"},
      {"plane --swatch " + sw + " --size nan 5 -o o.obj", "o.obj"},
      {"plane --swatch " + sw + " --size -3 5 -o o.obj", "o.obj"},
      {"plane --swatch " + sw + " --size 5 -o o.obj", "o.obj"},
      {"plane --swatch " + sw + " --size 5 5 --cell 100 -o o.obj", "o.obj"},
      {"plane --swatch " + sw + " --size 5 5 --threads -1 -o o.obj", "o.obj"},
      {"plane --swatch " + sw + " --size 5 5 -o o.xyz", "o.xyz"},
      {"plane --swatch " + sw + " --size 5 5 -o o.obj --stats nodir/s.json", "o.obj"},
      {"plane --swatch " + sw + " --size 5 5 -o nodir/o.obj", "nodir/o.obj"},
      {"info missing.obj", ""},
      {"info truncated.off", ""},
      {"render missing.obj -o o.png", "o.png"},
      {"render nan.off -o o.png", "o.png"},
      {"swatch chainmail --rows 0 -o o.obj", "o.obj"},
      {"swatch chainmail -o nodir/o.obj", "nodir/o.obj"},
  };
  const std::vector<std::string> before = listing(dir);
  for (const Case& c : cases) {
    for (const bool existing : {false, true}) {
      if (existing && c.out.empty()) continue;
      const std::string path = dir + "/" + c.out;
      if (existing) {
        if (!fs::exists(fs::path(path).parent_path())) continue;
        spit(path, "sentinel");
      }
      const CliRun r = meshquilt(dir, c.args);
      SCOPED_TRACE(c.args + (existing ? " (existing output)" : ""));
      EXPECT_FALSE(r.signaled);
      EXPECT_NE(r.status, 0);
      EXPECT_LT(r.status, 128);
      const auto lines = r.err_lines();
      EXPECT_EQ(lines.size(), 1u) << r.err;
      if (!lines.empty()) {
        EXPECT_EQ(lines[0].rfind("meshquilt", 0), 0u) << lines[0];
      }
      if (!c.out.empty()) {
        if (existing) {
          EXPECT_TRUE(slurp(path) == "sentinel") << "the existing output was modified";
          fs::remove(path);
        } else {
          EXPECT_FALSE(fs::exists(path));
        }
      }
      EXPECT_EQ(listing(dir), before);
    }
  }
}

TEST(Cli, NonManifoldSwatchDoesNotCrash) {
  const std::string dir = test::temp_dir();
  // Three triangles on one edge (a non-manifold fin) next to a closed tetrahedron.
  spit(dir + "/fin.obj",
       "v 0 0 0\nv 2 0 0\nv 1 1 0.2\nv 1 -1 0.2\nv 1 0.3 -0.2\n"
       "f 1 2 3\nf 2 1 4\nf 1 2 5\n"
       "v 3 0 0\nv 4 0 0\nv 3.5 1 0\nv 3.5 0.4 0.4\n"
       "f 6 8 7\nf 6 7 9\nf 7 8 9\nf 8 6 9\n");
  const CliRun r = meshquilt(dir, "plane --swatch fin.obj --size 6 4 -o o.obj --quiet");
  EXPECT_FALSE(r.signaled);
  EXPECT_LT(r.status, 128);
  if (r.status == 0) {
    EXPECT_TRUE(fs::exists(dir + "/o.obj"));
  } else {
    const auto lines = r.err_lines();
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("meshquilt", 0), 0u);
    EXPECT_FALSE(fs::exists(dir + "/o.obj"));
  }
}

TEST(Cli, QuietPrintsNothing) {
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  const CliRun r = meshquilt(dir, "plane --swatch " + sw + " --size 6 6 -o o.obj --quiet");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(fs::exists(dir + "/o.obj"));
}

TEST(Cli, ProgressLinesOnStderrWhenNotATerminal) {
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  const CliRun r = meshquilt(dir, "plane --swatch " + sw + " --size 8 7 -o o.obj");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto lines = r.err_lines();
  ASSERT_FALSE(lines.empty());
  // Plain lines (no carriage returns: stderr is a file), ending with the stage at 100%.
  EXPECT_EQ(r.err.find('\r'), std::string::npos);
  for (const std::string& line : lines) EXPECT_EQ(line.rfind('[', 0), 0u) << line;
  EXPECT_NE(lines.back().find("writing 100%"), std::string::npos) << lines.back();
  EXPECT_NE(r.err.find("quilting 100%"), std::string::npos) << r.err;
  // The summary goes to stdout, not stderr.
  EXPECT_NE(r.out.find("iterations"), std::string::npos) << r.out;
}

TEST(Cli, ProgressLinesForOtherPrograms) {
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  const CliRun r =
      meshquilt(dir, "plane --swatch " + sw + " --size 8 6 -o p.ply --progress-lines --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  int lines = 0;
  for (const std::string& line : r.err_lines()) {
    // progress STAGE FRACTION ELAPSED_S REMAINING_S
    std::istringstream in(line);
    std::string word, stage;
    double fraction = -1, elapsed = -1, remaining = -2;
    in >> word >> stage >> fraction >> elapsed >> remaining;
    ASSERT_TRUE(in && word == "progress") << line;
    EXPECT_TRUE(fraction >= 0 && fraction <= 1 && elapsed >= 0 && remaining >= -1) << line;
    ++lines;
  }
  EXPECT_GE(lines, 1);
}

TEST(Cli, OutputsCarryElementsKindsAndNormals) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, "swatch ivy --count 4 --length 6 -o ivy.obj --quiet").status, 0);
  const std::string job = "plane --swatch ivy.obj --size 10 8 --quiet";
  ASSERT_EQ(meshquilt(dir, job + " -o e.obj").status, 0);
  ASSERT_EQ(meshquilt(dir, job + " -o k.obj --groups kind").status, 0);
  ASSERT_EQ(meshquilt(dir, job + " -o n.obj --groups none --no-normals").status, 0);
  ASSERT_EQ(meshquilt(dir, job + " -o g.glb").status, 0);
  ASSERT_EQ(meshquilt(dir, job + " -o p.ply").status, 0);
  const auto count = [](const std::string& text, const std::string& prefix) {
    int n = 0;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) n += line.rfind(prefix, 0) == 0;
    return n;
  };
  const std::string e = slurp(dir + "/e.obj"), k = slurp(dir + "/k.obj"), n = slurp(dir + "/n.obj");
  const CliRun info = meshquilt(dir, "info e.obj --json");
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_EQ(count(e, "o "), std::stoi(json_value(info.out, "elements")));
  // info counts elements per kind: a vine or more, and the rest leaves.
  EXPECT_GE(std::stoi(json_value(info.out, "vine")), 1) << info.out;
  EXPECT_EQ(std::stoi(json_value(info.out, "vine")) + std::stoi(json_value(info.out, "leaf")),
            std::stoi(json_value(info.out, "elements")));
  EXPECT_GT(count(e, "vn "), 0);
  EXPECT_EQ(count(k, "o "), 2);  // vine and leaf
  EXPECT_EQ(count(n, "o "), 0);
  EXPECT_EQ(count(n, "vn "), 0);
  for (const std::string* text : {&e, &k, &n}) {
    EXPECT_GE(count(*text, "usemtl vine"), 1);
    EXPECT_GE(count(*text, "usemtl leaf"), 1);
    EXPECT_EQ(count(*text, "mtllib "), 1);
  }
  EXPECT_NE(slurp(dir + "/e.mtl").find("newmtl leaf"), std::string::npos);
  EXPECT_EQ(slurp(dir + "/g.glb").substr(0, 4), "glTF");
  EXPECT_NE(slurp(dir + "/p.ply").find("property int element_id"), std::string::npos);
  // The same geometry whatever the grouping: info reads the same counts.
  for (const char* f : {"k.obj", "n.obj", "p.ply"}) {
    const CliRun i = meshquilt(dir, std::string("info ") + f + " --json");
    EXPECT_EQ(json_value(i.out, "faces"), json_value(info.out, "faces")) << f;
    EXPECT_EQ(json_value(i.out, "elements"), json_value(info.out, "elements")) << f;
  }
  // Bad --groups, and an output's .mtl named as another output, are refused before work.
  const CliRun bad = meshquilt(dir, job + " -o b.obj --groups rings");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--groups"), std::string::npos) << bad.err;
  const CliRun clash = meshquilt(dir, job + " -o b.obj --stats b.mtl");
  EXPECT_EQ(clash.status, 1);
  EXPECT_FALSE(fs::exists(dir + "/b.obj") || fs::exists(dir + "/b.mtl"));
  // Reading a .glb is refused by name.
  const CliRun read = meshquilt(dir, "info g.glb");
  EXPECT_EQ(read.status, 1);
  EXPECT_NE(read.err.find("output format"), std::string::npos) << read.err;
}

TEST(Cli, RenderWritesAPng) {
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  const CliRun r = meshquilt(dir, "render " + sw + " -o pic.png --width 64 --height 48 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string png = slurp(dir + "/pic.png");
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // IHDR: width and height big-endian at bytes 16 and 20.
  auto be32 = [&](size_t at) {
    return (static_cast<unsigned char>(png[at]) << 24) |
           (static_cast<unsigned char>(png[at + 1]) << 16) |
           (static_cast<unsigned char>(png[at + 2]) << 8) | static_cast<unsigned char>(png[at + 3]);
  };
  EXPECT_EQ(be32(16), 64u);
  EXPECT_EQ(be32(20), 48u);
}

// Issue 13's structure measure as a user runs it: on a quilted plane of the default job's coarse
// sheet, interior rings keep the swatch's 4 links, nothing folds, and the figures are in --json.
TEST(Cli, InfoLinksMeasuresAQuiltedPlane) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(
      meshquilt(dir, "swatch chainmail --rows 3 --cols 3 --detail 16 -o sw.obj --quiet").status, 0);
  ASSERT_EQ(meshquilt(dir, "plane --swatch sw.obj --size 12 12 -o p.obj --quiet").status, 0);
  const CliRun t = meshquilt(dir, "info p.obj --links --swatch sw.obj --intersections");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("structure kept:    100.00% of interior rings link 4 others"),
            std::string::npos)
      << t.out;
  EXPECT_NE(t.out.find("self-intersecting elements: 0"), std::string::npos) << t.out;
  const CliRun j = meshquilt(dir, "info p.obj --links --swatch sw.obj --json");
  ASSERT_EQ(j.status, 0) << j.err;
  EXPECT_EQ(json_value(j.out, "interior_links"), "4");
  EXPECT_GE(std::stod(json_value(j.out, "share_with_swatch_links")), 0.98);
  EXPECT_GE(std::stod(json_value(j.out, "density_ratio")), 0.95);
  EXPECT_EQ(json_value(j.out, "isolated_rings"), "0");
  // --swatch without --links is a usage error.
  EXPECT_EQ(meshquilt(dir, "info p.obj --swatch sw.obj").status, 2);
}

// The surface command's methods on a generated flat base: auto takes the global method for the
// chain mail sheet and reproduces the plane's structure; patches runs too; a bad name is a
// usage error. The base drawn under the texture renders.
TEST(Cli, SurfaceMethodsAndRenderWithTheBase) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(
      meshquilt(dir, "swatch chainmail --rows 3 --cols 3 --detail 16 -o sw.obj --quiet").status, 0);
  const TriMesh grid = test::plane_grid(10, 10, 20, 20);
  std::ostringstream obj;
  for (int v = 0; v < grid.num_vertices(); ++v)
    obj << "v " << grid.V(v, 0) << " " << grid.V(v, 1) << " " << grid.V(v, 2) << "\n";
  for (int f = 0; f < grid.num_faces(); ++f)
    obj << "f " << grid.F(f, 0) + 1 << " " << grid.F(f, 1) + 1 << " " << grid.F(f, 2) + 1 << "\n";
  spit(dir + "/grid.obj", obj.str());
  const std::string job = "surface --base grid.obj --swatch sw.obj --scale 0.07 --field 1 0 0";
  const CliRun a = meshquilt(dir, job + " -o a.obj --stats a.json --quiet");
  ASSERT_EQ(a.status, 0) << a.err;
  const std::string stats = slurp(dir + "/a.json");
  EXPECT_NE(stats.find("\"method\": \"global\""), std::string::npos);
  EXPECT_GE(std::stod(json_value(stats, "share_with_swatch_links")), 0.98);
  EXPECT_EQ(json_value(stats, "removed_self_intersecting"), "0");
  // info --scale takes surface's --scale (relative to the base) and agrees with its stats.
  const CliRun i =
      meshquilt(dir,
                "info a.obj --links --swatch sw.obj --base grid.obj --scale 0.07 --json "
                "--elements e.csv");
  ASSERT_EQ(i.status, 0) << i.err;
  EXPECT_NEAR(std::stod(json_value(i.out, "density_ratio")),
              std::stod(json_value(stats, "density_ratio")), 1e-6);
  EXPECT_NEAR(std::stod(json_value(i.out, "density_ratio")), 1.0, 0.08);
  const std::string csv = slurp(dir + "/e.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "element,x,y,z,size,area,ring,links,interior,long,length,interior_ends,kind,defect,"
            "loop_links,wire,opening,fold_degrees,size_ratio,aspect,stretch,by_correspondence");
  EXPECT_EQ(static_cast<int>(std::count(csv.begin(), csv.end(), '\n')) - 1,
            std::stoi(json_value(i.out, "rings")));
  EXPECT_EQ(meshquilt(dir, "info a.obj --links --swatch sw.obj --scale 0.07").status, 2);
  const CliRun p = meshquilt(dir, job + " --method patches -o p.obj --stats p.json --quiet");
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_NE(slurp(dir + "/p.json").find("\"method\": \"patches\""), std::string::npos);
  EXPECT_EQ(meshquilt(dir, job + " --method bogus -o b.obj").status, 2);
  EXPECT_FALSE(fs::exists(dir + "/b.obj"));
  const CliRun r = meshquilt(
      dir, "render a.obj --base grid.obj --color links -o pic.png --width 64 --height 48 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir + "/pic.png").substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const CliRun c = meshquilt(dir, "render a.obj --crop 100 100 100 1 -o none.png");
  EXPECT_EQ(c.status, 1);
  EXPECT_EQ(c.err_lines().size(), 1u);
  EXPECT_FALSE(fs::exists(dir + "/none.png"));
}

// The ivy section grows as vines (issue 23 item 4): auto takes them, the stems climb (+Y by
// default on this upright plane) many swatch vines long with the swatch's leaves per length,
// and nothing intersects; --method vines refuses a swatch that is not a vine.
TEST(Cli, SurfaceGrowsIvyAsVines) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, "swatch ivy --count 2 --length 2 -o ivy.obj --quiet").status, 0);
  ASSERT_EQ(meshquilt(dir, "swatch apples --count 4 -o apples.obj --quiet").status, 0);
  const TriMesh grid = test::plane_grid(2, 1.5, 20, 15);
  std::ostringstream obj;
  for (int v = 0; v < grid.num_vertices(); ++v)
    obj << "v " << grid.V(v, 0) << " " << grid.V(v, 1) << " " << grid.V(v, 2) << "\n";
  for (int f = 0; f < grid.num_faces(); ++f)
    obj << "f " << grid.F(f, 0) + 1 << " " << grid.F(f, 1) + 1 << " " << grid.F(f, 2) + 1 << "\n";
  spit(dir + "/grid.obj", obj.str());
  const CliRun a = meshquilt(
      dir, "surface --base grid.obj --swatch ivy.obj --scale 0.06 -o a.obj --stats a.json");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_NE(a.out.find(" stems (spacing "), std::string::npos) << a.out;
  const std::string stats = slurp(dir + "/a.json");
  EXPECT_NE(stats.find("\"method\": \"vines\""), std::string::npos);
  EXPECT_GE(std::stod(json_value(stats, "long_length_ratio")), 3.0);
  EXPECT_NEAR(std::stod(json_value(stats, "compact_per_length_ratio")), 1.0, 0.15);
  const CliRun i = meshquilt(dir, "info a.obj --intersections --links --swatch ivy.obj --json");
  ASSERT_EQ(i.status, 0) << i.err;
  EXPECT_EQ(json_value(i.out, "intersecting_face_pairs"), "0");
  EXPECT_GE(std::stod(json_value(i.out, "long_length_ratio")), 3.0);
  const CliRun v = meshquilt(
      dir, "surface --base grid.obj --swatch apples.obj --scale 0.06 --method vines -o v.obj");
  EXPECT_EQ(v.status, 1);
  EXPECT_EQ(v.err_lines().size(), 1u);
  EXPECT_FALSE(fs::exists(dir + "/v.obj"));
}

// Issue 23's honest measure as a user runs it, on the square 4-in-1 sheet quilted on a plane:
// each ring judged against its own kind's count (flat rings 4, connectors 2) keeps 100%, no ring
// is degenerate, every element is a copy of its swatch element's size and shape; the figures
// are in the text, the JSON and the elements CSV, and render --color shape draws them.
TEST(Cli, InfoLinksJudgesEachKindAndMeasuresShapes) {
  const std::string dir = test::temp_dir();
  const CliRun h = meshquilt(dir, "swatch --help");
  EXPECT_NE(h.out.find("chainmail-square"), std::string::npos) << h.out;
  ASSERT_EQ(
      meshquilt(dir, "swatch chainmail-square --rows 4 --cols 4 --detail 16 -o sw.obj --quiet")
          .status,
      0);
  ASSERT_EQ(meshquilt(dir, "plane --swatch sw.obj --size 20 20 -o p.obj --quiet").status, 0);
  const CliRun t = meshquilt(dir, "info p.obj --links --swatch sw.obj --elements e.csv");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("interior link count per ring kind: ring 4, connector 2"), std::string::npos)
      << t.out;
  EXPECT_NE(t.out.find("structure kept:    100.00% of interior rings link as many others as their "
                       "kind in the swatch"),
            std::string::npos)
      << t.out;
  EXPECT_NE(t.out.find("ring:            100.00% of"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("connector:       100.00% of"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("degenerate rings:  0 (none)"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("size ratio:      median 1.000, 90th 1.000, 99th 1.000, largest 1.000"),
            std::string::npos)
      << t.out;
  const CliRun j = meshquilt(dir, "info p.obj --links --swatch sw.obj --json");
  ASSERT_EQ(j.status, 0) << j.err;
  EXPECT_EQ(std::stod(json_value(j.out, "share_with_swatch_links")), 1.0);
  EXPECT_EQ(json_value(j.out, "kind"), "\"ring\"");
  EXPECT_EQ(std::stod(json_value(j.out, "share")), 1.0);
  EXPECT_EQ(json_value(j.out, "degenerate_rings"), "0");
  EXPECT_NEAR(std::stod(json_value(j.out, "p99")), 1.0, 1e-6);
  EXPECT_EQ(json_value(j.out, "stretched_elements"), "0");
  // One CSV line per element, each a copy of a swatch element of its kind.
  const std::string csv = slurp(dir + "/e.csv");
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);
  int rows = 0, connectors = 0;
  while (std::getline(lines, line)) {
    ++rows;
    connectors += line.find(",connector,none,") != std::string::npos;
    EXPECT_EQ(line.substr(line.size() - 2), ",1") << line;  // by correspondence
  }
  EXPECT_EQ(rows, std::stoi(json_value(j.out, "rings")));
  EXPECT_GT(connectors, rows / 2);
  // render --color shape needs the swatch; with it, a picture.
  EXPECT_EQ(meshquilt(dir, "render p.obj --color shape -o s.png").status, 2);
  EXPECT_FALSE(fs::exists(dir + "/s.png"));
  const CliRun r = meshquilt(
      dir, "render p.obj --color shape --swatch sw.obj -o s.png --width 64 --height 48 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir + "/s.png").substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const CliRun l = meshquilt(
      dir, "render p.obj --color links --swatch sw.obj -o l.png --width 64 --height 48 --quiet");
  ASSERT_EQ(l.status, 0) << l.err;
}

TEST(Cli, PlaneIsByteIdenticalAcrossThreadsAndDevices) {
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  const std::string common = "plane --swatch " + sw + " --size 8 7 --variety 0.2 --seed 5 --quiet";
  // One name in three directories: an OBJ names its .mtl, so files of one name are compared.
  for (const char* sub : {"t1", "t2", "cl"}) fs::create_directory(dir + "/" + sub);
  ASSERT_EQ(meshquilt(dir, common + " --device cpu --threads 1 -o t1/q.obj").status, 0);
  ASSERT_EQ(meshquilt(dir, common + " --device cpu --threads 2 -o t2/q.obj").status, 0);
  const std::string t1 = slurp(dir + "/t1/q.obj"), m1 = slurp(dir + "/t1/q.mtl");
  ASSERT_FALSE(t1.empty());
  ASSERT_FALSE(m1.empty());
  EXPECT_TRUE(t1 == slurp(dir + "/t2/q.obj")) << "--threads 1 and 2 differ";
  EXPECT_TRUE(m1 == slurp(dir + "/t2/q.mtl")) << "--threads 1 and 2 differ";
  if (!opencl_platform_present()) GTEST_SKIP() << "clinfo -l lists no OpenCL platform";
  const CliRun g = meshquilt(dir, common + " --device opencl --threads 2 -o cl/q.obj");
  ASSERT_EQ(g.status, 0) << g.err;
  EXPECT_TRUE(t1 == slurp(dir + "/cl/q.obj")) << "--device cpu and opencl differ";
}

// Built with a sanitizer: its allocator replaces glibc's malloc (no tunables, no mallopt).
constexpr bool sanitized_build() {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
  return true;
#else
  return false;
#endif
#else
  return false;
#endif
}

// Whether this machine and build can run on transparent huge pages on request (cli/huge_pages.h):
// glibc 2.35 or later, the kernel's THP mode "madvise", no sanitizer. A run that does not ask
// for them (MESHQUILT_HUGE_PAGES=1) also needs its start's probe to find the huge page faster.
bool huge_pages_possible() {
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35))
  return !sanitized_build() &&
         slurp("/sys/kernel/mm/transparent_hugepage/enabled").find("[madvise]") !=
             std::string::npos;
#else
  return false;
#endif
}

// Whether the engine can keep freed blocks for its next arrays: glibc's malloc, no sanitizer.
bool kept_possible() {
#if defined(__GLIBC__)
  return !sanitized_build();
#else
  return false;
#endif
}

TEST(Cli, SurfaceIsByteIdenticalOnHugePages) {
  // The engine restarts itself once on huge pages where it can (--stats says so); the bytes must
  // not depend on it, and MESHQUILT_HUGE_PAGES=0 or the tunable set by the caller stop the restart.
  const std::string dir = test::temp_dir();
  const std::string sw = small_swatch(dir);
  write_obj(dir + "/grid.obj", test::plane_grid(3, 3, 6, 6));  // about 50 rings: 37 s under ASan
  const std::string job = "surface --base grid.obj --swatch " + sw + " --scale 0.3 --quiet";
  for (const char* sub : {"on", "off", "set"}) fs::create_directory(dir + "/" + sub);
  ASSERT_EQ(meshquilt(dir, job + " -o on/q.obj --stats on/q.json").status, 0);
  ASSERT_EQ(setenv("MESHQUILT_HUGE_PAGES", "0", 1), 0);
  const CliRun off = meshquilt(dir, job + " -o off/q.obj --stats off/q.json");
  unsetenv("MESHQUILT_HUGE_PAGES");
  ASSERT_EQ(off.status, 0) << off.err;
  fs::create_directory(dir + "/asked");
  ASSERT_EQ(setenv("MESHQUILT_HUGE_PAGES", "1", 1), 0);
  const CliRun asked = meshquilt(dir, job + " -o asked/q.obj --stats asked/q.json");
  unsetenv("MESHQUILT_HUGE_PAGES");
  ASSERT_EQ(asked.status, 0) << asked.err;
  ASSERT_EQ(setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=0", 1), 0);
  const CliRun set = meshquilt(dir, job + " -o set/q.obj --stats set/q.json");
  unsetenv("GLIBC_TUNABLES");
  ASSERT_EQ(set.status, 0) << set.err;
  // Freed blocks kept for the run's next arrays (cli/huge_pages.h keep_freed_memory), or not.
  fs::create_directory(dir + "/unkept");
  ASSERT_EQ(setenv("MESHQUILT_KEEP_FREED", "0", 1), 0);
  const CliRun unkept = meshquilt(dir, job + " -o unkept/q.obj --stats unkept/q.json");
  unsetenv("MESHQUILT_KEEP_FREED");
  ASSERT_EQ(unkept.status, 0) << unkept.err;
  // Kept where the run is not on huge pages (there a fresh block's faults cost little).
  for (const char* sub : {"on", "off", "asked", "set"}) {
    const std::string stats = slurp(dir + "/" + sub + "/q.json");
    EXPECT_EQ(json_value(stats, "freed_memory_kept"),
              kept_possible() && json_value(stats, "huge_pages") == "false" ? "true" : "false")
        << sub;
  }
  EXPECT_EQ(json_value(slurp(dir + "/unkept/q.json"), "freed_memory_kept"), "false");
  // The default run follows its own probe, whose figures --stats gives.
  const std::string on_stats = slurp(dir + "/on/q.json");
  mq::cli::PageProbe probe;
  probe.small_us = std::stod(json_value(on_stats, "page_probe_small_us"));
  probe.huge_us = std::stod(json_value(on_stats, "page_probe_huge_us"));
  EXPECT_EQ(probe.small_us >= 0, huge_pages_possible()) << on_stats;
  EXPECT_EQ(json_value(on_stats, "huge_pages"),
            huge_pages_possible() && probe.huge_pays() ? "true" : "false");
  EXPECT_EQ(json_value(slurp(dir + "/asked/q.json"), "huge_pages"),
            huge_pages_possible() ? "true" : "false");
  EXPECT_EQ(json_value(slurp(dir + "/asked/q.json"), "page_probe_small_us"), "-1");
  EXPECT_EQ(json_value(slurp(dir + "/off/q.json"), "huge_pages"), "false");
  EXPECT_EQ(json_value(slurp(dir + "/set/q.json"), "huge_pages"), "false");
  const std::string on = slurp(dir + "/on/q.obj");
  ASSERT_FALSE(on.empty());
  EXPECT_TRUE(on == slurp(dir + "/off/q.obj"));
  EXPECT_TRUE(on == slurp(dir + "/set/q.obj"));
  EXPECT_TRUE(on == slurp(dir + "/asked/q.obj"));
  EXPECT_TRUE(on == slurp(dir + "/unkept/q.obj"));
}

// The probe measures both page sizes (on Linux) and prefers the huge page only when it is faster.
TEST(Cli, PageProbeMeasuresBothPageSizes) {
  const mq::cli::PageProbe probe = mq::cli::first_touch_probe();
#if defined(__linux__)
  EXPECT_GT(probe.small_us, 0);
  EXPECT_GT(probe.huge_us, 0);
#endif
  EXPECT_EQ(probe.huge_pays(),
            probe.huge_us >= 0 && probe.small_us >= 0 && probe.huge_us < probe.small_us);
  mq::cli::PageProbe unmeasured;
  EXPECT_FALSE(unmeasured.huge_pays());
  unmeasured.small_us = 100;
  EXPECT_FALSE(unmeasured.huge_pays());
  unmeasured.huge_us = 10;
  EXPECT_TRUE(unmeasured.huge_pays());
}

}  // namespace
}  // namespace mq
