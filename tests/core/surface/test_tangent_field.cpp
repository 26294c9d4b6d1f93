#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/surface/tangent_field.h"
#include "tests/test_support.h"

namespace mq {
namespace {

Vector3d row3(const MatrixX3d& M, int i) { return M.row(i).transpose(); }

void expect_unit_tangent(const TriMesh& m, const MatrixX3d& T) {
  ASSERT_EQ(T.rows(), m.F.rows());
  const MatrixX3d N = face_normals(m.V, m.F);
  for (int f = 0; f < T.rows(); ++f) {
    ASSERT_NEAR(T.row(f).norm(), 1.0, 1e-9) << "face " << f;
    ASSERT_LT(std::abs(T.row(f).dot(N.row(f))), 1e-9) << "face " << f;
  }
}

// Mean angle (radians) between the vectors of edge-adjacent faces, the neighbour's vector
// projected into the face's plane.
double mean_adjacent_angle(const TriMesh& m, const MatrixX3d& T) {
  const MatrixX3i TT = face_adjacency(edge_topology(m.F, m.num_vertices()));
  const MatrixX3d N = face_normals(m.V, m.F);
  double sum = 0;
  int count = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = TT(f, k);
      if (g < 0) continue;
      Vector3d t = row3(T, g) - row3(T, g).dot(row3(N, f)) * row3(N, f);
      if (t.norm() < 1e-12) continue;
      sum += std::acos(std::clamp(t.normalized().dot(row3(T, f)), -1.0, 1.0));
      ++count;
    }
  return sum / count;
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = test::temp_dir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "no InvalidInput thrown";
}

TriMesh load(const std::string& name) { return read_mesh(test::shared_data("base/" + name)); }

TEST(TangentField, ConstantDirectionOnAPlane) {
  const TriMesh grid = test::plane_grid(2, 1, 6, 4);
  const MatrixX3d T = tangent_field_from_direction(grid.V, grid.F, Vector3d(1, 1, 0));
  expect_unit_tangent(grid, T);
  for (int f = 0; f < T.rows(); ++f)
    EXPECT_LT((row3(T, f) - Vector3d(1, 1, 0).normalized()).norm(), 1e-12);
  // An oblique direction is projected.
  const MatrixX3d P = tangent_field_from_direction(grid.V, grid.F, Vector3d(0, 3, 4));
  for (int f = 0; f < P.rows(); ++f) EXPECT_LT((row3(P, f) - Vector3d(0, 1, 0)).norm(), 1e-12);
  // Parallel to the normal everywhere: no direction along the surface, refused in words (issue
  // 28; it used to fall back to the longest bounding-box axis without a word).
  try {
    tangent_field_from_direction(grid.V, grid.F, Vector3d(0, 0, -2));
    ADD_FAILURE() << "a direction normal to the base everywhere was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("normal to the base everywhere"), std::string::npos)
        << e.what();
  }
  // Normal to some faces only (a box's top, with a direction along z): followed on the others.
  const MatrixX3d B =
      tangent_field_from_direction(test::unit_cube().V, test::unit_cube().F, Vector3d(0, 0, 1));
  EXPECT_TRUE(B.allFinite());
  EXPECT_THROW(tangent_field_from_direction(grid.V, grid.F, Vector3d::Zero()), InvalidInput);
}

TEST(TangentField, DirectionFieldOnCurvedMeshesIsUnitTangent) {
  for (const char* name : {"bunny_igl_7k.off", "cup_mug_11k.off", "teapot_6k.obj"}) {
    SCOPED_TRACE(name);
    const TriMesh m = load(name);
    expect_unit_tangent(m, tangent_field_from_direction(m.V, m.F, Vector3d(0, 0, 1)));
  }
  // A cube face whose normal is the direction is filled from its neighbours, in its plane.
  const TriMesh cube = test::unit_cube();
  const MatrixX3d T = tangent_field_from_direction(cube.V, cube.F, Vector3d(0, 0, 1));
  expect_unit_tangent(cube, T);
  EXPECT_LT((row3(T, 4) - row3(T, 5)).norm(), 1e-12);  // the two top triangles agree
}

TEST(TangentField, VertexVectorsFromFile) {
  const TriMesh grid = test::plane_grid(1, 1, 2, 2);  // 9 vertices
  std::string text = "# vectors\n";
  for (int v = 0; v < 9; ++v) text += "1 0 0.5  # vertex\n\n";
  const MatrixX3d X = read_vertex_vector_field(write_file("good.txt", text), 9);
  ASSERT_EQ(X.rows(), 9);
  EXPECT_EQ(row3(X, 8), Vector3d(1, 0, 0.5));
  const MatrixX3d T = tangent_field_from_vertex_vectors(grid.V, grid.F, X);
  expect_unit_tangent(grid, T);
  for (int f = 0; f < T.rows(); ++f) EXPECT_LT((row3(T, f) - Vector3d(1, 0, 0)).norm(), 1e-12);

  const std::string bad = write_file("bad.txt", "1 0 0\n# c\n1 0\n");
  EXPECT_NE(error_of([&] { read_vertex_vector_field(bad, 9); }).find("bad.txt:3"),
            std::string::npos);
  const std::string word = write_file("word.txt", "1 0 0\n1 x 0\n");
  EXPECT_NE(error_of([&] { read_vertex_vector_field(word, 9); }).find("word.txt:2"),
            std::string::npos);
  const std::string nan = write_file("nan.txt", "1 0 nan\n");
  EXPECT_NE(error_of([&] { read_vertex_vector_field(nan, 9); }).find("nan.txt:1"),
            std::string::npos);
  const std::string few = write_file("few.txt", "1 0 0\n");
  EXPECT_NE(error_of([&] { read_vertex_vector_field(few, 9); }).find("1 vectors for 9"),
            std::string::npos);
  const std::string many = write_file("many.txt", "1 0 0\n1 0 0\n");
  EXPECT_NE(error_of([&] { read_vertex_vector_field(many, 1); }).find("many.txt:2"),
            std::string::npos);
  EXPECT_THROW(read_vertex_vector_field(test::temp_dir() + "/missing.txt", 9), InvalidInput);
  EXPECT_THROW(tangent_field_from_vertex_vectors(grid.V, grid.F, X.topRows(4)), InvalidInput);
  // All-zero vectors give no direction anywhere: an error, not a silent default (issue 14).
  EXPECT_THROW(tangent_field_from_vertex_vectors(grid.V, grid.F, MatrixX3d::Zero(9, 3)),
               InvalidInput);
}

TEST(TangentField, KeyVectorReaderRejectsMalformedLines) {
  const std::string good = write_file("keys.txt", "# keys\n3 1 0 0\n\n7 0 1 0 # second\n");
  const std::vector<KeyVector> keys = read_key_vectors(good, 10);
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_EQ(keys[1].vertex, 7);
  EXPECT_EQ(keys[1].direction, Vector3d(0, 1, 0));
  const std::pair<const char*, const char*> bad[] = {
      {"3 1 0\n", "k.txt:1"},    {"1 0 0 1\n3.5 1 0 0\n", "k.txt:2"}, {"10 1 0 0\n", "k.txt:1"},
      {"-1 1 0 0\n", "k.txt:1"}, {"2 1 0 0\n2 0 1 0\n", "k.txt:2"},   {"2 0 0 0\n", "k.txt:1"},
      {"2 1 inf 0\n", "k.txt:1"}};
  for (const auto& [text, where] : bad) {
    const std::string path = write_file("k.txt", text);
    EXPECT_NE(error_of([&] { read_key_vectors(path, 10); }).find(where), std::string::npos) << text;
  }
}

TEST(TangentField, KeyVectorDiffusionOnTheBunny) {
  const TriMesh m = load("bunny_igl_7k.off");
  const MatrixX3d VN = vertex_normals(m.V, m.F);
  const MatrixX3d FN = face_normals(m.V, m.F);
  // Keys that disagree strongly: the normal crossed with a fixed axis, at three vertices.
  std::vector<KeyVector> keys;
  for (int v : {100, 2000, 3000})
    keys.push_back({v, row3(VN, v).cross(Vector3d(0.3, 1, 0.2)).normalized()});
  const MatrixX3d T = tangent_field_from_key_vectors(m.V, m.F, keys);
  expect_unit_tangent(m, T);
  const MatrixX3d X = vertex_field_from_key_vectors(m.V, m.F, keys);
  ASSERT_EQ(X.rows(), m.V.rows());
  for (const KeyVector& k : keys) {
    EXPECT_LT((row3(X, k.vertex) - k.direction).norm(), 1e-9);
    // The faces around the key follow it (compared in each face's plane; faces nearly
    // orthogonal to the key's tangent plane are skipped).
    for (int f = 0; f < m.F.rows(); ++f) {
      if (!(m.F.row(f).array() == k.vertex).any()) continue;
      const Vector3d p = k.direction - k.direction.dot(row3(FN, f)) * row3(FN, f);
      if (p.norm() < 0.5) continue;
      EXPECT_GT(row3(T, f).dot(p.normalized()), std::cos(20 * M_PI / 180)) << "face " << f;
    }
  }
  for (int v = 0; v < X.rows(); ++v) {
    ASSERT_NEAR(X.row(v).norm(), 1.0, 1e-9);
    ASSERT_LT(std::abs(X.row(v).dot(VN.row(v))), 1e-9);
  }
  EXPECT_LT(mean_adjacent_angle(m, T), 15 * M_PI / 180);
  // Keys taken from a smooth field give a field about as smooth.
  const MatrixX3d S = vertex_tangent_field(m.V, m.F, smooth_tangent_field(m.V, m.F));
  std::vector<KeyVector> consistent;
  for (int v = 0; v < m.V.rows(); v += 500) consistent.push_back({v, row3(S, v)});
  const MatrixX3d C = tangent_field_from_key_vectors(m.V, m.F, consistent);
  expect_unit_tangent(m, C);
  // (the smooth default itself has a mean of about 4.4 degrees here, from curvature).
  EXPECT_LT(mean_adjacent_angle(m, C),
            1.5 * mean_adjacent_angle(m, smooth_tangent_field(m.V, m.F)));
  // Errors.
  EXPECT_THROW(tangent_field_from_key_vectors(m.V, m.F, {}), InvalidInput);
  EXPECT_THROW(tangent_field_from_key_vectors(m.V, m.F, {{-1, Vector3d(1, 0, 0)}}), InvalidInput);
  EXPECT_THROW(tangent_field_from_key_vectors(m.V, m.F, {{5, row3(VN, 5)}}), InvalidInput);
  EXPECT_THROW(tangent_field_from_key_vectors(m.V, m.F, {keys[0], keys[0]}), InvalidInput);
}

TEST(TangentField, KeyVectorsOnAMultiComponentMesh) {
  const TriMesh m = load("teapot_6k.obj");
  const MatrixX3d VN = vertex_normals(m.V, m.F);
  const int v = m.F(0, 0);
  const std::vector<KeyVector> keys{{v, row3(VN, v).unitOrthogonal()}};
  expect_unit_tangent(m, tangent_field_from_key_vectors(m.V, m.F, keys));
  const MatrixX3d X = vertex_field_from_key_vectors(m.V, m.F, keys);
  EXPECT_TRUE(X.allFinite());
}

TEST(TangentField, SmoothDefaultFieldIsSmoothAndDeterministic) {
  const TriMesh bunny = load("bunny_igl_7k.off");
  const MatrixX3d T = smooth_tangent_field(bunny.V, bunny.F);
  expect_unit_tangent(bunny, T);
  const double smooth = mean_adjacent_angle(bunny, T);
  EXPECT_LT(smooth, 15 * M_PI / 180);
  EXPECT_LE(smooth, mean_adjacent_angle(bunny, smooth_tangent_field(bunny.V, bunny.F, 0)));
  EXPECT_EQ(T, smooth_tangent_field(bunny.V, bunny.F));
  for (const char* name :
       {"cup_mug_11k.off", "teapot_6k.obj", "lilium_7k.obj", "knight_decimated_1k.off"}) {
    SCOPED_TRACE(name);
    const TriMesh m = load(name);
    expect_unit_tangent(m, smooth_tangent_field(m.V, m.F));
  }
  const TriMesh torus = test::torus(2, 0.5, 40, 20);
  expect_unit_tangent(torus, smooth_tangent_field(torus.V, torus.F));
  EXPECT_THROW(smooth_tangent_field(torus.V, torus.F, -1), InvalidInput);
}

TEST(TangentField, VertexFieldFromFaceField) {
  const TriMesh m = load("knight_decimated_1k.off");
  const MatrixX3d T = smooth_tangent_field(m.V, m.F);
  const MatrixX3d X = vertex_tangent_field(m.V, m.F, T);
  const MatrixX3d N = vertex_normals(m.V, m.F);
  for (int v = 0; v < X.rows(); ++v) {
    ASSERT_NEAR(X.row(v).norm(), 1.0, 1e-9);
    ASSERT_LT(std::abs(X.row(v).dot(N.row(v))), 1e-9);
  }
  EXPECT_THROW(vertex_tangent_field(m.V, m.F, T.topRows(3)), InvalidInput);
}

}  // namespace
}  // namespace mq
