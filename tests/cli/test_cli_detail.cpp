// --detail F (issue 26's Preview): the same job with each swatch element simplified to a share of
// its faces. The layout is the full run's (the method and the lattice are decided at full
// detail), the rings keep their links, the output has about that share of the faces, and a
// value outside (0, 1] is refused in one line before any work.
#include <gtest/gtest.h>

#include <string>

#include "core/mesh/mesh_io.h"
#include "tests/cli/cli_support.h"

namespace mq {
namespace {

double number(const std::string& json, const std::string& key) {
  const std::string v = json_value(json, key);
  EXPECT_FALSE(v.empty()) << key;
  return v.empty() ? 0.0 : std::stod(v);
}

// Blender's default UV sphere (32 x 16) under the sample chain mail (6 x 6 rings of 1,152 faces):
// measured 646 rings placed either way, 690k -> 69k faces, 3.1 -> 1.2 s, links 89.3 -> 86.2%
// (a coarse ring's long chords meet a neighbour sooner where the shell bends it: 7 more removed).
TEST(CliDetail, APreviewIsTheFullRunsLayoutAtAShareOfTheFaces) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, "swatch chainmail -o sw.obj --quiet").status, 0);
  write_obj(dir + "/sphere.obj", test::uv_sphere(1, 32, 16));
  const std::string job = "surface --base sphere.obj --swatch sw.obj --scale 0.3 --quiet";
  const CliRun full = meshquilt(dir, job + " -o full.ply --stats full.json");
  ASSERT_EQ(full.status, 0) << full.err;
  const CliRun preview = meshquilt(dir, job + " --detail 0.1 -o preview.ply --stats preview.json");
  ASSERT_EQ(preview.status, 0) << preview.err;
  const std::string a = slurp(dir + "/full.json"), b = slurp(dir + "/preview.json");
  // The same layout: the global method, the same elements placed.
  EXPECT_EQ(json_value(b, "method"), "\"global\"");
  EXPECT_EQ(json_value(a, "method"), "\"global\"");
  EXPECT_EQ(json_value(b, "seamless"), json_value(a, "seamless"));
  EXPECT_EQ(number(b, "placed"), number(a, "placed"));
  EXPECT_GT(number(a, "placed"), 100);
  // The elements and faces written: nearly all the same rings, a tenth of the faces.
  const TriMesh fa = read_mesh(dir + "/full.ply"), fb = read_mesh(dir + "/preview.ply");
  const double elements_a = number(a, "elements"), elements_b = number(b, "elements");
  EXPECT_NEAR(elements_b / elements_a, 1.0, 0.03) << elements_a << " " << elements_b;
  EXPECT_LT(fb.num_faces(), 0.12 * fa.num_faces());
  EXPECT_GT(fb.num_faces(), 0.08 * fa.num_faces());
  EXPECT_EQ(number(b, "median_faces_before"), 1152);
  EXPECT_LE(number(b, "median_faces_after"), 120);
  EXPECT_EQ(number(b, "distinct_elements"), 1);  // the sheet's rings are copies of one
  EXPECT_EQ(number(b, "kept_finer"), 0);
  // Links kept as at full detail (a coarse ring still has its hole), and no more degenerate.
  const double links_a = number(a, "share_with_swatch_links");
  const double links_b = number(b, "share_with_swatch_links");
  EXPECT_GT(links_a, 0.85);
  EXPECT_GT(links_b, links_a - 0.05) << links_a;
  EXPECT_LE(number(b, "degenerate_rings"), number(a, "degenerate_rings") + 3);
  EXPECT_GE(number(b, "coverage"), 0.98);
  // The estimate follows the detail; it writes nothing, so it needs no -o.
  const CliRun ea = meshquilt(dir, job + " --estimate");
  const CliRun eb = meshquilt(dir, job + " --detail 0.1 -o e.ply --estimate");
  ASSERT_EQ(ea.status, 0) << ea.err;
  ASSERT_EQ(eb.status, 0) << eb.err;
  const double est_a = std::stod(ea.out.substr(ea.out.find("faces ") + 6));
  const double est_b = std::stod(eb.out.substr(eb.out.find("faces ") + 6));
  EXPECT_NEAR(est_b / fb.num_faces(), 1.0, 0.1) << est_b << " " << fb.num_faces();
  EXPECT_LT(est_b, 0.12 * est_a);
}

TEST(CliDetail, PlaneTakesItAndBadValuesAreRefusedInOneLine) {
  const std::string dir = test::temp_dir();
  ASSERT_EQ(meshquilt(dir, "swatch chainmail --rows 3 --cols 3 -o sw.obj --quiet").status, 0);
  const CliRun full = meshquilt(dir, "plane --swatch sw.obj --size 12 12 -o a.obj --quiet");
  ASSERT_EQ(full.status, 0) << full.err;
  const CliRun low =
      meshquilt(dir, "plane --swatch sw.obj --size 12 12 --detail 0.3 -o b.obj --stats b.json");
  ASSERT_EQ(low.status, 0) << low.err;
  EXPECT_NE(low.out.find("swatch at detail 0.3: 9 elements (1 distinct, 0 kept finer"),
            std::string::npos)
      << low.out;
  const TriMesh a = read_mesh(dir + "/a.obj"), b = read_mesh(dir + "/b.obj");
  EXPECT_LT(b.num_faces(), 0.4 * a.num_faces());
  EXPECT_GT(b.num_faces(), 0.2 * a.num_faces());
  for (const std::string bad : {"0", "-0.5", "1.5", "nan", "x"}) {
    for (const std::string command :
         {"plane --swatch sw.obj --size 12 12", "surface --base b.obj --swatch sw.obj"}) {
      const CliRun r = meshquilt(dir, command + " --detail " + bad + " -o c.obj");
      EXPECT_EQ(r.status, 2) << command << " " << bad;
      EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
      EXPECT_NE(r.err.find("--detail"), std::string::npos) << r.err;
    }
  }
  EXPECT_FALSE(fs::exists(dir + "/c.obj"));
}

}  // namespace
}  // namespace mq
