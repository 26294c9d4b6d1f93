// Issue 14's cases, run as a user would: every bad input, impossible size or clashing path
// ends in under the timeout with exit 1 or 2, one line naming the problem, and nothing written;
// or, where the input is valid, a correct result.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "core/mesh/mesh_io.h"
#include "tests/cli/cli_support.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// A 2 x 2 grid of squares as an OFF base (9 vertices, 8 faces), with extra face lines.
std::string grid_off(const std::string& extra_faces = "", int extra = 0) {
  std::string s = "OFF\n9 " + std::to_string(8 + extra) + " 0\n";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) s += std::to_string(i) + " " + std::to_string(j) + " 0\n";
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i, b = a + 1, c = a + 4, d = a + 3;
      s += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
      s += "3 " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
    }
  return s + extra_faces;
}

std::string binary_ply_header(const std::string& elements_before, long long vertices) {
  return "ply\nformat binary_little_endian 1.0\n" + elements_before + "element vertex " +
         std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n";
}

std::string one_triangle_binary() {
  std::string body;
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  body.append(reinterpret_cast<const char*>(v), sizeof v);
  body.push_back(3);
  const int32_t f[3] = {0, 1, 2};
  body.append(reinterpret_cast<const char*>(f), sizeof f);
  return body;
}

class Reliability : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir();
    const CliRun r =
        meshquilt(dir_, "swatch chainmail --rows 2 --cols 2 --detail 16 -o sw.obj --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    spit(dir_ + "/grid.off", grid_off());
  }
  // Runs args with a generous timeout (the target is 5 s; a hang or an hour-long job fails)
  // and expects exit 1 or 2, one line containing `message`, and the directory unchanged.
  void expect_refused(const std::string& args, const std::string& message) {
    SCOPED_TRACE(args);
    const std::vector<std::string> before = listing(dir_);
    const auto t0 = std::chrono::steady_clock::now();
    const CliRun r = meshquilt(dir_, args, 60);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_FALSE(r.signaled) << "killed (status " << r.status << ")";
    EXPECT_TRUE(r.status == 1 || r.status == 2) << r.status << ": " << r.err;
    const auto lines = r.err_lines();
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_NE(lines[0].find(message), std::string::npos) << lines[0];
    EXPECT_LT(seconds, 20.0);
    EXPECT_EQ(listing(dir_), before);
  }
  std::string dir_;
};

TEST_F(Reliability, DeclaredCountsAreBoundedByTheData) {
  spit(dir_ + "/big.off", "OFF\n268435456 1 0\n0 0 0\n");  // the 24-byte file
  expect_refused("info big.off", "need more data than the file's");
  spit(dir_ + "/huge.off", "OFF\n2147483647 2147483647 0\n0 0 0\n3 0 0 0\n");
  expect_refused("info huge.off", "need more data than the file's");
  spit(dir_ + "/big.ply", binary_ply_header("", 2000000000) + std::string(40, '\0'));
  expect_refused("info big.ply", "element 'vertex' count 2000000000 needs more data");
  spit(dir_ + "/big_ascii.ply",
       "ply\nformat ascii 1.0\nelement vertex 100000000\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n");
  expect_refused("plane --swatch big_ascii.ply --size 5 5 -o o.obj", "needs more data");
}

TEST_F(Reliability, ElementsWithoutPropertiesAreSkipped) {
  std::string empty_elements;
  for (int i = 0; i < 100; ++i)
    empty_elements += "element junk" + std::to_string(i) + " 2147483647\n";
  spit(dir_ + "/junk.ply", binary_ply_header(empty_elements, 3) + one_triangle_binary());
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun r = meshquilt(dir_, "info junk.ply");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("faces:             1\n"), std::string::npos) << r.out;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

TEST_F(Reliability, NonRegularFilesAreRefused) {
  ASSERT_EQ(::mkfifo((dir_ + "/pipe.off").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir_ + "/keys.txt").c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", dir_ + "/zero.obj");
  fs::create_symlink("/dev/urandom", dir_ + "/random.ply");
  fs::create_symlink("/dev/zero", dir_ + "/zero_keys.txt");
  expect_refused("info pipe.off", "is a pipe (FIFO), not a regular file");
  expect_refused("info zero.obj", "is a device, not a regular file");
  expect_refused("info random.ply", "is a device, not a regular file");
  expect_refused("surface --base grid.off --swatch sw.obj --keys keys.txt -o o.obj",
                 "is a pipe (FIFO)");
  expect_refused("surface --base grid.off --swatch sw.obj --keys zero_keys.txt -o o.obj",
                 "is a device");
  expect_refused("surface --base grid.off --swatch sw.obj --field-file pipe.off -o o.obj",
                 "is a pipe (FIFO)");
}

TEST_F(Reliability, NoGeometryIsAnErrorNotAnEmptyFile) {
  // Every face listed twice, or one duplicated face: the duplicates are dropped (and counted),
  // and the result is the same as for the grid itself.
  std::string twice = grid_off();
  const size_t faces_at = twice.find("\n3 ");
  twice = "OFF\n9 16 0\n" + twice.substr(twice.find('\n', 4) + 1) + twice.substr(faces_at + 1);
  spit(dir_ + "/twice.off", twice);
  spit(dir_ + "/dup.off", grid_off("3 4 5 8\n", 1));
  const CliRun ref = meshquilt(dir_, "surface --base grid.off --swatch sw.obj -o ref.ply --quiet");
  ASSERT_EQ(ref.status, 0) << ref.err;
  for (const char* base : {"twice.off", "dup.off"}) {
    const CliRun r = meshquilt(dir_, std::string("surface --base ") + base +
                                         " --swatch sw.obj -o o.ply --stats s.json --quiet");
    ASSERT_EQ(r.status, 0) << base << ": " << r.err;
    EXPECT_TRUE(slurp(dir_ + "/o.ply") == slurp(dir_ + "/ref.ply")) << base;
    EXPECT_EQ(json_value(slurp(dir_ + "/s.json"), "duplicate_faces"),
              std::string(base) == "dup.off" ? "1" : "8");
    fs::remove(dir_ + "/o.ply");
    fs::remove(dir_ + "/s.json");
  }
  // Every face listed again facing the other way (a two-sided sheet, enclosing nothing): the
  // backs go, counted and said, and the result is the grid's. It placed no element before,
  // blaming the scale.
  std::string backs;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i, b = a + 1, c = a + 4, d = a + 3;
      backs += "3 " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(b) + "\n";
      backs += "3 " + std::to_string(a) + " " + std::to_string(d) + " " + std::to_string(c) + "\n";
    }
  spit(dir_ + "/backs.off", grid_off(backs, 8));
  {
    const CliRun r =
        meshquilt(dir_, "surface --base backs.off --swatch sw.obj -o o.ply --stats s.json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("base: two-sided (each face listed again facing the other way"),
              std::string::npos)
        << r.out;
    EXPECT_TRUE(slurp(dir_ + "/o.ply") == slurp(dir_ + "/ref.ply"));
    EXPECT_EQ(json_value(slurp(dir_ + "/s.json"), "sheet_back_faces"), "8");
    EXPECT_EQ(json_value(slurp(dir_ + "/s.json"), "duplicate_faces"), "0");
    fs::remove(dir_ + "/o.ply");
    fs::remove(dir_ + "/s.json");
  }
  // One face with its back inside a one-sided grid (the wicker chair has 35) stays.
  spit(dir_ + "/one_back.off", grid_off("3 0 4 1\n", 1));
  {
    const CliRun r =
        meshquilt(dir_,
                  "surface --base one_back.off --swatch sw.obj -o o.ply --stats s.json --quiet "
                  "--min-coverage 0");
    EXPECT_EQ(json_value(slurp(dir_ + "/s.json"), "sheet_back_faces"), "0") << r.err;
    fs::remove(dir_ + "/o.ply");
    fs::remove(dir_ + "/s.json");
  }
  fs::remove(dir_ + "/ref.ply");
  spit(dir_ + "/degenerate.off", grid_off("3 4 4 8\n", 1));
  expect_refused("surface --base degenerate.off --swatch sw.obj -o o.obj", "repeats a vertex");
  spit(dir_ + "/point.off", "OFF\n3 1 0\n1 1 1\n1 1 1\n1 1 1\n3 0 1 2\n");
  expect_refused("surface --base point.off --swatch sw.obj -o o.obj", "zero size");
  // Distinct vertices on a line (a mesh flattened to an edge): no area, said so, not the
  // direction field's failed solve.
  spit(dir_ + "/line.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n3 0 1 2\n3 1 3 2\n");
  expect_refused("surface --base line.off --swatch sw.obj -o o.obj", "has no area");
  expect_refused("surface --base grid.off --swatch sw.obj --scale 10 -o o.obj --quiet",
                 "nothing written");
}

TEST_F(Reliability, SizesThatCannotFitAreRefusedBeforeWork) {
  expect_refused("plane --swatch sw.obj --size 1e6 0.5 -o o.obj", "--max-faces");
  expect_refused("plane --swatch sw.obj --size 8 8 --cell 1e-3 -o o.obj", "use a larger --cell");
  expect_refused("plane --swatch sw.obj --size 8 8 --cell 0.01 -o o.obj", "use a larger --cell");
  expect_refused("surface --base grid.off --swatch sw.obj --scale 1e-6 -o o.obj",
                 "use a larger --scale");
  expect_refused("swatch chainmail --rows 200 --cols 200 --detail 256 -o o.obj", "--max-faces");
  expect_refused("swatch weave --rows 200 --cols 200 --detail 256 -o o.obj", "--max-faces");
  expect_refused("plane --swatch sw.obj --size 5 5 --max-faces 10 -o o.obj", "limit of 10");
  // The override lets a job through that the default would also allow.
  const CliRun ok = meshquilt(dir_, "plane --swatch sw.obj --size 5 5 --max-faces 1e6 -o o.obj");
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// Issue 23: Blender's UV sphere (triangle fans at the poles) with the sample chain mail drove
// the engine to 23.5 GB. The estimate covers the global layout (counted before it is built),
// a memory limit refuses a job up front, and the peak stays within 1.5x of the estimate.
TEST_F(Reliability, MemoryIsEstimatedAndBounded) {
  write_mesh(dir_ + "/uv.obj", test::uv_sphere(1.0, 32, 16));
  expect_refused("surface --base uv.obj --swatch sw.obj --scale 0.05 --max-memory 0.02 -o o.obj",
                 "--max-memory");
  const CliRun r =
      meshquilt(dir_, "surface --base uv.obj --swatch sw.obj --scale 0.1 -o o.obj --stats s.json");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string stats = slurp(dir_ + "/s.json");
  const auto number = [&](const std::string& key) {
    const size_t at = stats.find("\"" + key + "\":");
    EXPECT_NE(at, std::string::npos) << key;
    return std::stod(stats.substr(at + key.size() + 3));
  };
  const double estimated = number("estimated_bytes"), peak = number("peak_bytes");
  std::printf("[ measure  ] UV sphere: estimated %.0f MiB, peak %.0f MiB\n", estimated / (1 << 20),
              peak / (1 << 20));
  EXPECT_GT(number("estimated_faces"), 0.5 * number("faces"));
  EXPECT_LE(peak, 1.5 * estimated);
}

TEST_F(Reliability, MessagesInTheUsersTerms) {
  spit(dir_ + "/far.off", "OFF\n3 1 0\n-1e308 0 0\n1e308 0 0\n0 1e308 0\n3 0 1 2\n");
  expect_refused("info far.off", "coordinates too large");
  expect_refused("plane --swatch sw.obj --size 8 -o o.obj", "expects L W (2 values), got 1");
  spit(dir_ + "/tiny.off",
       "OFF\n4 2 0\n0 0 0\n1e-310 0 0\n1e-310 1e-310 0\n0 1e-310 1e-311\n"
       "3 0 1 2\n3 0 2 3\n");
  expect_refused("plane --swatch tiny.off --size 5 5 -o o.obj", "too small or too large");
  // The file's own bytes in a message: escaped, not echoed raw nor cut at a NUL.
  spit(dir_ + "/bytes.off", std::string("\xff\xfe\0OFF\x01 3 1 0\n", 13));
  expect_refused("info bytes.off", "missing OFF header (found '\\xff\\xfe\\x00OFF\\x01')");
  spit(dir_ + "/zero.txt", std::string(9 * 2, ' ') +
                               "\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n"
                               "0 0 0\n0 0 0\n0 0 0\n0 0 0\n");
  expect_refused("surface --base grid.off --swatch sw.obj --field-file zero.txt -o o.obj",
                 "all zero");
  // Issue 28, also weak: a flat swatch is named and explained, not "shell map: height must be
  // finite and > 0"; coordinates whose extent overflows give no "about -nan faces".
  spit(dir_ + "/flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_refused("surface --base grid.off --swatch flat.obj -o o.obj",
                 "flat.obj: the swatch is flat");
  spit(dir_ + "/huge.obj",
       "v 0 0 0\nv 1e300 0 0\nv 0 1e300 0\nv 0 0 1e300\n"
       "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n");
  expect_refused("surface --base huge.obj --swatch sw.obj -o o.obj",
                 "huge.obj: coordinates too large");
}

TEST_F(Reliability, OutputPathsAreCheckedBeforeWork) {
  expect_refused("plane --swatch sw.obj --size 5 5 -o o.obj --stats o.obj", "two outputs");
  expect_refused("plane --swatch sw.obj --size 5 5 -o o.obj --stats ./o.obj", "two outputs");
  const std::string swatch_before = slurp(dir_ + "/sw.obj");
  expect_refused("plane --swatch sw.obj --size 5 5 -o o.obj --stats sw.obj", "is also an input");
  expect_refused("plane --swatch sw.obj --size 5 5 -o sw.obj", "is also an input");
  EXPECT_TRUE(slurp(dir_ + "/sw.obj") == swatch_before);
  expect_refused("surface --base grid.off --swatch sw.obj -o grid.off", "is also an input");
  expect_refused("info sw.obj --links --elements sw.obj", "is also an input");
  fs::create_directory(dir_ + "/sub.obj");
  expect_refused("plane --swatch sw.obj --size 5 5 -o sub.obj", "is a directory");
  if (::geteuid() != 0) {  // root writes into read-only directories
    fs::create_directory(dir_ + "/ro");
    fs::permissions(dir_ + "/ro", fs::perms::owner_read | fs::perms::owner_exec);
    expect_refused("plane --swatch sw.obj --size 5 5 -o o.obj --stats ro/s.json",
                   "cannot write in the directory");
    fs::permissions(dir_ + "/ro", fs::perms::owner_all);
  }
}

// Issue 28, item 8: a guidance direction normal to a flat base everywhere guides nothing; it is
// refused like an all-zero field, in words, not replaced by the unguided field.
TEST_F(Reliability, GuidanceWithNothingAlongTheSurfaceIsRefused) {
  expect_refused("surface --base grid.off --swatch sw.obj --field 0 0 1 -o o.obj",
                 "normal to the base everywhere");
  expect_refused("surface --base grid.off --swatch sw.obj --field 0 0 -3 -o o.obj",
                 "normal to the base everywhere");
}

// Issue 28, item 7: faces meeting three at an edge (a fin) are borders for the layout; the run
// says so in its summary rather than leaving the user to find the texture ending there.
TEST_F(Reliability, NonManifoldEdgesAreSaid) {
  // The grid's interior edges 1-4 and 4-8 get a third face: a fin folded back over the grid.
  spit(dir_ + "/fin.off", grid_off("3 1 4 8\n", 1));
  const CliRun r = meshquilt(dir_,
                             "surface --base fin.off --swatch sw.obj --scale 0.3 -o f.obj "
                             "--min-coverage 0");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("base: 2 non-manifold edges (three or more faces meeting) are borders"),
            std::string::npos)
      << r.out;
  for (const char* f : {"f.obj", "f.mtl", "fin.off"}) fs::remove(dir_ + "/" + f);
}

// Issue 28, item 7: a sphere with a fin (a triangle standing out of it) on every 7th edge was
// 88% covered after 13 s and refused with a message blaming the scale (larger fins: 1.9% and
// exit 0). The fins are left out and said; the sphere they stand on is covered.
TEST_F(Reliability, FinsAreLeftOutAndTheSurfaceTheyStandOnIsCovered) {
  TriMesh sphere = test::uv_sphere(1.0, 32, 16);
  const Eigen::Index faces = sphere.F.rows();
  int fins = 0;
  for (Eigen::Index f = 0; f < faces; f += 7, ++fins) {
    const int a = sphere.F(f, 0), b = sphere.F(f, 1);
    const Vector3d mid = 0.5 * (sphere.V.row(a) + sphere.V.row(b)).transpose();
    sphere.V.conservativeResize(sphere.V.rows() + 1, 3);
    sphere.V.row(sphere.V.rows() - 1) = (1.3 * mid).transpose();
    sphere.F.conservativeResize(sphere.F.rows() + 1, 3);
    sphere.F.row(sphere.F.rows() - 1) << a, b, static_cast<int>(sphere.V.rows()) - 1;
  }
  write_mesh(dir_ + "/fins.obj", sphere);
  const CliRun r = meshquilt(dir_, "surface --base fins.obj --swatch sw.obj --scale 0.2 -o f.obj");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("base: " + std::to_string(fins) + " faces in fins"), std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("are borders"), std::string::npos) << r.out;
  const size_t at = r.out.find("% of the base covered");
  ASSERT_NE(at, std::string::npos) << r.out;
  const size_t start = r.out.rfind(' ', at - 1) + 1;
  EXPECT_GE(std::stod(r.out.substr(start, at - start)), 98.0) << r.out;
  for (const char* f : {"f.obj", "f.mtl", "fins.obj", "fins.mtl"}) fs::remove(dir_ + "/" + f);
}

// Issue 26: `surface --estimate` prints the job's size in one machine-readable line and writes
// nothing. Through the global layout (the sample 3 x 3 sheet, a lattice) it counts the copies
// the run places: within 10% of the faces written. Through the patches it is whole swatch copies
// over the area: for a sheet the patches cut (the fixture's 2 x 2 sheet is not a lattice) never
// under the faces written, at most twice them (1.74x here); for apples, which the patches pack
// as the swatch packs them, within 10% (0.94-1.05 measured on a flat sheet, a torus and Venus).
// The vines: within 10% (0.97 here). `fits` follows --max-faces.
TEST_F(Reliability, EstimateIsOneLineAndHolds) {
  write_mesh(dir_ + "/sphere.obj", test::uv_sphere(1.0, 32, 16));
  ASSERT_EQ(
      meshquilt(dir_, "swatch chainmail --rows 3 --cols 3 --detail 16 -o sw3.obj --quiet").status,
      0);
  // The vines (issue 28: 20% over): their stems at the spacing, times the share of the area
  // evenly spaced streamlines fill.
  ASSERT_EQ(meshquilt(dir_, "swatch ivy --count 2 --length 2 -o ivy.obj --quiet").status, 0);
  ASSERT_EQ(meshquilt(dir_, "swatch apples --count 11 -o ap.obj --quiet").status, 0);
  for (const auto& [swatch, lo, hi] : {std::tuple<std::string, double, double>{"sw3.obj", 0.9, 1.1},
                                       {"sw.obj", 1.0, 2.0},
                                       {"ap.obj", 0.9, 1.1},
                                       {"ivy.obj", 0.9, 1.1}}) {
    SCOPED_TRACE(swatch);
    const std::string job =
        "surface --base sphere.obj --swatch " + swatch + " --scale 0.15 -o s.obj";
    const std::vector<std::string> before = listing(dir_);
    const CliRun e = meshquilt(dir_, job + " --estimate");
    ASSERT_EQ(e.status, 0) << e.err;
    EXPECT_EQ(listing(dir_), before) << "--estimate wrote something";
    double faces = 0, bytes = 0, seconds = 0;
    int fits = -1;
    ASSERT_EQ(std::sscanf(e.out.c_str(), "estimate faces %lf bytes %lf seconds %lf fits %d", &faces,
                          &bytes, &seconds, &fits),
              4)
        << e.out;
    EXPECT_EQ(fits, 1);
    EXPECT_GT(bytes, faces);
    EXPECT_GT(seconds, 0);
    ASSERT_EQ(meshquilt(dir_, job + " --quiet").status, 0);
    const double written = read_mesh(dir_ + "/s.obj").num_faces();
    EXPECT_GE(faces / written, lo) << faces << " estimated, " << written << " written";
    EXPECT_LE(faces / written, hi) << faces << " estimated, " << written << " written";
    const CliRun small = meshquilt(dir_, job + " --estimate --max-faces 1000");
    ASSERT_EQ(small.status, 0) << small.err;
    EXPECT_NE(small.out.find(" fits 0"), std::string::npos) << small.out;
    for (const char* f : {"s.obj", "s.mtl"}) fs::remove(dir_ + "/" + f);
  }
  for (const char* f :
       {"sphere.obj", "sphere.mtl", "sw3.obj", "sw3.mtl", "ivy.obj", "ivy.mtl", "ap.obj", "ap.mtl"})
    fs::remove(dir_ + "/" + f);
}

// Issue 28: an output name with a line break would split the OBJ's `mtllib` line; one that is not
// UTF-8 cannot be written into --stats' JSON. Both are refused in words before any work; an
// input named so is recorded in --stats as valid JSON (the byte as the code point of its value).
TEST_F(Reliability, OutputNamesMustBeText) {
  expect_refused("plane --swatch sw.obj --size 5 5 -o \"$(printf 'a\\nb.obj')\"", "line break");
  expect_refused("plane --swatch sw.obj --size 5 5 -o \"$(printf 'a\\377.obj')\"", "not UTF-8");
  expect_refused("plane --swatch sw.obj --size 5 5 -o o.obj --stats \"$(printf 's\\377.json')\"",
                 "not UTF-8");
  fs::copy_file(dir_ + "/sw.obj", dir_ + "/sw\xff.obj");
  const CliRun r = meshquilt(
      dir_,
      "plane --swatch \"$(printf 'sw\\377.obj')\" --size 5 5 -o o.obj --stats s.json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string stats = slurp(dir_ + "/s.json");
  EXPECT_NE(stats.find("sw\\u00ff.obj"), std::string::npos);
  EXPECT_EQ(stats.find('\xff'), std::string::npos) << "a byte that is not UTF-8 in the JSON";
  fs::remove(dir_ + "/sw\xff.obj");
  for (const char* f : {"o.obj", "o.mtl", "s.json"}) fs::remove(dir_ + "/" + f);
}

// A full disk, simulated by a file size limit (RLIMIT_FSIZE, with SIGXFSZ ignored so that the
// write fails with EFBIG as it would with ENOSPC): exit 1, one line naming the output, the old
// file at the path untouched and no temporary file left (issue 14).
TEST_F(Reliability, AFullDiskLeavesTheOldFileAndNoTemporary) {
  spit(dir_ + "/big.obj", "old\n");
  spit(dir_ + "/big.mtl", "old mtl\n");
  spit(dir_ + "/big.json", "old stats\n");
  const std::vector<std::string> before = listing(dir_);
  const std::string err = dir_ + "/.err";
  // dash's ulimit -f counts 512-byte blocks: 64 KiB, far less than the layer's OBJ.
  const std::string cmd =
      "cd '" + dir_ + "' && trap '' XFSZ && ulimit -f 128 && exec '" + std::string(MESHQUILT_CLI) +
      "' plane --swatch sw.obj --size 12 12 -o big.obj --stats big.json --quiet 2>'" + err +
      "' </dev/null >/dev/null";
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw)) << "killed by signal " << WTERMSIG(raw);
  EXPECT_EQ(WEXITSTATUS(raw), 1);
  const std::string message = slurp(err);
  fs::remove(err);
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  EXPECT_NE(message.find("big."), std::string::npos) << message;
  EXPECT_EQ(slurp(dir_ + "/big.obj"), "old\n");
  EXPECT_EQ(slurp(dir_ + "/big.mtl"), "old mtl\n") << "the .mtl of the old OBJ was replaced";
  EXPECT_EQ(slurp(dir_ + "/big.json"), "old stats\n") << "the stats of the old OBJ were replaced";
  EXPECT_EQ(listing(dir_), before);
}

}  // namespace
}  // namespace mq
