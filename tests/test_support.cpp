#include "tests/test_support.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace mq::test {

std::string blender_base(const std::string& name) {
  return std::string(MESHQUILT_BLENDER_BASES) + "/" + name;
}

std::string shared_data(const std::string& relative) {
  return std::string(MESHQUILT_SHARED_DATA) + "/" + relative;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void spit(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string temp_dir() {
  // ctest runs each test in its own process, several at once: a suite's SetUpTestSuite (no
  // current test) and parameterised tests must not share a directory across processes.
  const auto* unit = ::testing::UnitTest::GetInstance();
  const auto* info = unit->current_test_info();
  const auto* suite = unit->current_test_suite();
  std::string name = "meshquilt_test_" + std::to_string(::getpid());
  if (info)
    name += std::string("_") + info->test_suite_name() + "_" + info->name();
  else if (suite)
    name += std::string("_") + suite->name();
  for (char& c : name)
    if (c == '/') c = '_';
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  // Named by process, so removed when the process ends (MESHQUILT_KEEP_TEST_DIRS=1 keeps them
  // to look at a failure).
  struct Cleanup {
    std::vector<std::filesystem::path> dirs;
    ~Cleanup() {
      const char* keep = std::getenv("MESHQUILT_KEEP_TEST_DIRS");
      if (keep && std::string(keep) == "1") return;
      std::error_code ec;
      for (const auto& d : dirs) std::filesystem::remove_all(d, ec);
    }
  };
  static Cleanup cleanup;
  cleanup.dirs.push_back(dir);
  return dir.string();
}

TriMesh unit_cube() {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) << (i & 1), (i >> 1) & 1, (i >> 2) & 1;
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3,  // z = 0, normal -z
      4, 5, 6, 5, 7, 6,     // z = 1, normal +z
      0, 1, 4, 1, 5, 4,     // y = 0, normal -y
      2, 6, 3, 3, 6, 7,     // y = 1, normal +y
      0, 4, 2, 2, 4, 6,     // x = 0, normal -x
      1, 3, 5, 3, 7, 5;     // x = 1, normal +x
  return m;
}

TriMesh torus(double R, double r, int n, int m) {
  TriMesh t;
  t.V.resize(n * m, 3);
  t.F.resize(2 * n * m, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / m;
      t.V.row(i * m + j) << (R + r * std::cos(v)) * std::cos(u),
          (R + r * std::cos(v)) * std::sin(u), r * std::sin(v);
      const int a = i * m + j, b = ((i + 1) % n) * m + j, c = ((i + 1) % n) * m + (j + 1) % m,
                d = i * m + (j + 1) % m;
      t.F.row(2 * (i * m + j)) << a, b, c;
      t.F.row(2 * (i * m + j) + 1) << a, c, d;
    }
  return t;
}

TriMesh plane_grid(double w, double h, int nx, int ny) {
  TriMesh g;
  g.V.resize((nx + 1) * (ny + 1), 3);
  g.F.resize(2 * nx * ny, 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) g.V.row(j * (nx + 1) + i) << w * i / nx, h * j / ny, 0.0;
  int f = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
      g.F.row(f++) << a, b, c;
      g.F.row(f++) << a, c, d;
    }
  return g;
}

TriMesh uv_sphere(double r, int segments, int rings) {
  TriMesh m;
  const int rows = rings - 1;  // vertex rows between the poles
  m.V.resize(rows * segments + 2, 3);
  for (int i = 0; i < rows; ++i) {
    const double phi = M_PI * (i + 1) / rings;
    for (int j = 0; j < segments; ++j) {
      const double theta = 2 * M_PI * j / segments;
      m.V.row(i * segments + j) << r * std::sin(phi) * std::cos(theta),
          r * std::sin(phi) * std::sin(theta), r * std::cos(phi);
    }
  }
  const int north = rows * segments, south = north + 1;
  m.V.row(north) << 0, 0, r;
  m.V.row(south) << 0, 0, -r;
  std::vector<Eigen::Vector3i> f;
  for (int j = 0; j < segments; ++j) {
    const int k = (j + 1) % segments;
    f.emplace_back(north, j, k);
    f.emplace_back(south, (rows - 1) * segments + k, (rows - 1) * segments + j);
    for (int i = 0; i + 1 < rows; ++i) {
      const int a = i * segments + j, b = i * segments + k, c = (i + 1) * segments + j,
                d = (i + 1) * segments + k;
      f.emplace_back(a, c, d);
      f.emplace_back(a, d, b);
    }
  }
  m.F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row(static_cast<Eigen::Index>(i)) = f[i].transpose();
  return m;
}

TriMesh open_cylinder(double r, double h, int n, int m) {
  TriMesh c;
  c.V.resize(n * (m + 1), 3);
  c.F.resize(2 * n * m, 3);
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      c.V.row(j * n + i) << r * std::cos(a), r * std::sin(a), h * j / m;
    }
  int f = 0;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * n + i, b = j * n + (i + 1) % n, cc = (j + 1) * n + (i + 1) % n,
                d = (j + 1) * n + i;
      c.F.row(f++) << a, b, cc;
      c.F.row(f++) << a, cc, d;
    }
  return c;
}

void expect_same_points_on_coarse(const TriMesh& fine, const TriMesh& coarse, int stride,
                                  const std::function<void(int&, Vector3d&)>& to_coarse) {
  for (int f = 0; f < fine.num_faces(); f += stride) {
    const Vector3d b0(0.2, 0.3, 0.5);
    Vector3d p = Vector3d::Zero();
    for (int k = 0; k < 3; ++k) p += b0(k) * fine.V.row(fine.F(f, k)).transpose();
    int face = f;
    Vector3d b = b0;
    to_coarse(face, b);
    Vector3d q = Vector3d::Zero();
    for (int k = 0; k < 3; ++k) q += b(k) * coarse.V.row(coarse.F(face, k)).transpose();
    EXPECT_LT((p - q).norm(), 1e-12) << f;
    EXPECT_NEAR(b.sum(), 1.0, 1e-12);
    EXPECT_GE(b.minCoeff(), -1e-12);
  }
}

}  // namespace mq::test
