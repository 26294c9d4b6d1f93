// Issue 25 on real data: the armor quilt (5 x 6 chain mail on the knight, the Table 1 job)
// saved, then placed on the knight bent 20 degrees by a smooth bend: every element closed and
// manifold, none intersecting, the links and element sizes as at rest.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/mesh/mesh_io.h"
#include "tests/cli/cli_support.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// The mesh bent about the z axis along its y extent by `degrees` (scripts/bend_base.py).
TriMesh bent(TriMesh m, double degrees) {
  const double y0 = m.V.col(1).minCoeff(), length = m.V.col(1).maxCoeff() - y0;
  const double xc = 0.5 * (m.V.col(0).minCoeff() + m.V.col(0).maxCoeff());
  const double theta = degrees * M_PI / 180, R = length / theta;
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double phi = theta * (m.V(v, 1) - y0) / length, r = R - (m.V(v, 0) - xc);
    m.V(v, 0) = xc + R - r * std::cos(phi);
    m.V(v, 1) = y0 + r * std::sin(phi);
  }
  return m;
}

double number(const std::string& json, const std::string& key, size_t from = 0) {
  const size_t at = json.find("\"" + key + "\":", from);
  EXPECT_NE(at, std::string::npos) << key;
  return at == std::string::npos ? NAN : std::stod(json.substr(json.find(':', at) + 1));
}

TEST(FollowBaseKnight, TheArmorFollowsTheKnightBent) {
  const std::string dir = test::temp_dir();
  const std::string knight = test::shared_data("base/knight_decimated_1k.off");
  write_mesh(dir + "/bent.off", bent(read_mesh(knight), 20));
  ASSERT_EQ(meshquilt(dir, "swatch chainmail --rows 5 --cols 6 -o sw.obj --quiet").status, 0);
  CliRun r = meshquilt(dir, "surface --base '" + knight +
                                "' --swatch sw.obj --scale 0.13 -o rest.ply --save-quilt q.mqq "
                                "--quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  r = meshquilt(dir, "embed --quilt q.mqq --base bent.off -o bent.ply --stats e.json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string embed = slurp(dir + "/e.json");
  EXPECT_LE(number(embed, "removed"), 0.02 * number(embed, "elements"));
  auto measure = [&](const std::string& mesh, const std::string& base) {
    const CliRun m = meshquilt(dir, "info " + mesh +
                                        " --json --intersections --links --swatch "
                                        "sw.obj --base '" +
                                        base + "' --scale 0.13");
    EXPECT_EQ(m.status, 0) << m.err;
    return m.out;
  };
  const std::string rest = measure("rest.ply", knight), posed = measure("bent.ply", "bent.off");
  EXPECT_NE(posed.find("\"closed\": true"), std::string::npos);
  EXPECT_NE(posed.find("\"manifold\": true"), std::string::npos);
  EXPECT_EQ(number(posed, "intersecting_face_pairs"), 0);
  EXPECT_EQ(number(posed, "self_intersecting_elements"), 0);
  // Links within 2 points of the rest pose; element sizes within 5%.
  EXPECT_NEAR(number(posed, "share_with_swatch_links"), number(rest, "share_with_swatch_links"),
              0.02);
  const double rest_size = number(rest, "median", rest.find("\"size_ratio\""));
  const double posed_size = number(posed, "median", posed.find("\"size_ratio\""));
  EXPECT_NEAR(posed_size / rest_size, 1.0, 0.05);
}

}  // namespace
}  // namespace mq
