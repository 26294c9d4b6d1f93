#include "core/surface/tangent_field.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/input_file.h"
#include "core/mesh/mesh_topology.h"

namespace mq {
namespace {

// Below this relative length a projected vector is taken as parallel to the normal.
constexpr double kParallel = 1e-6;

Vector3d row3(const MatrixX3d& M, Eigen::Index i) { return M.row(i).transpose(); }

Vector3d tangent_part(const Vector3d& t, const Vector3d& n) { return t - t.dot(n) * n; }

void check_mesh(const MatrixX3d& V, const MatrixX3i& F) {
  MQ_CHECK(V.allFinite(), InvalidInput, "tangent field: non-finite vertex position");
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(F(f, k) >= 0 && F(f, k) < V.rows(), InvalidInput, "tangent field: face ", f,
               " has vertex index ", F(f, k), " out of range [0, ", V.rows(), ")");
}

// Coordinate axes ordered by decreasing bounding-box extent (stable: lower index first).
std::vector<int> axes_by_extent(const MatrixX3d& V, const MatrixX3i& F) {
  const Vector3d extent = bounding_box(V, F).extent();
  std::vector<int> axes{0, 1, 2};
  std::stable_sort(axes.begin(), axes.end(), [&](int a, int b) { return extent(a) > extent(b); });
  return axes;
}

// Projection of the longest bounding-box axis usable on a face with unit normal n.
Vector3d axis_fallback(const std::vector<int>& axes, const Vector3d& n) {
  for (int a : axes) {
    const Vector3d t = tangent_part(Vector3d::Unit(a), n);
    if (t.norm() > 0.1) return t.normalized();  // some axis has |n.e|^2 <= 1/3
  }
  return Vector3d::Unit(axes[0]);  // zero normal: any unit vector is orthogonal to it
}

// Fills the rows of T whose `defined` flag is 0 (see the header's common contract).
void fill_undefined(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N, MatrixX3d& T,
                    std::vector<char>& defined) {
  const int nf = static_cast<int>(F.rows());
  if (std::all_of(defined.begin(), defined.end(), [](char d) { return d != 0; })) return;
  const Adjacency vf = vertex_faces(F, static_cast<int>(V.rows()));
  std::vector<int> pending;
  for (int f = 0; f < nf; ++f)
    if (!defined[f]) pending.push_back(f);
  // Waves: each reads only faces defined before it, so the result is order-independent.
  std::vector<int> newly;
  std::vector<Vector3d> values;
  while (!pending.empty()) {
    newly.clear();
    values.clear();
    std::vector<int> still;
    for (int f : pending) {
      const Vector3d n = row3(N, f);
      Vector3d sum = Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        const int v = F(f, k);
        for (const int* g = vf.begin(v); g != vf.end(v); ++g)
          if (defined[*g] == 1) sum += tangent_part(row3(T, *g), n);
      }
      if (sum.norm() > kParallel) {
        newly.push_back(f);
        values.push_back(sum.normalized());
      } else {
        still.push_back(f);
      }
    }
    if (newly.empty()) break;
    for (size_t i = 0; i < newly.size(); ++i) {
      T.row(newly[i]) = values[i].transpose();
      defined[newly[i]] = 1;
    }
    pending.swap(still);
  }
  if (pending.empty()) return;
  const std::vector<int> axes = axes_by_extent(V, F);
  for (int f : pending) {
    T.row(f) = axis_fallback(axes, row3(N, f)).transpose();
    defined[f] = 1;
  }
}

// Field from one unnormalised vector per face: projected, normalised, undefined ones filled.
MatrixX3d finish_field(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& N,
                       const MatrixX3d& raw, double scale) {
  const int nf = static_cast<int>(F.rows());
  MatrixX3d T(nf, 3);
  std::vector<char> defined(nf, 0);
  for (int f = 0; f < nf; ++f) {
    const Vector3d t = tangent_part(row3(raw, f), row3(N, f));
    const double len = t.norm();
    if (len > kParallel * scale) {
      T.row(f) = (t / len).transpose();
      defined[f] = 1;
    } else {
      T.row(f).setZero();
    }
  }
  fill_undefined(V, F, N, T, defined);
  return T;
}

// Splits a data line (comment stripped) into whitespace-separated tokens.
std::vector<std::string> tokens_of(std::string line) {
  const size_t hash = line.find('#');
  if (hash != std::string::npos) line.resize(hash);
  std::istringstream is(line);
  std::vector<std::string> out;
  std::string t;
  while (is >> t) out.push_back(t);
  return out;
}

bool parse_double(const std::string& s, double& value) {
  errno = 0;
  char* end = nullptr;
  value = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && !s.empty() && std::isfinite(value);
}

bool parse_int(const std::string& s, long& value) {
  errno = 0;
  char* end = nullptr;
  value = std::strtol(s.c_str(), &end, 10);
  return end == s.c_str() + s.size() && !s.empty() && errno == 0;
}

// Calls on_line(tokens, line_number) for each non-empty data line of path.
template <typename OnLine>
void for_each_data_line(const std::string& path, const char* what, OnLine on_line) {
  const std::string file = std::string(what) + " file";
  // A regular file of bounded size (core/mesh/input_file): a FIFO or /dev/zero is refused.
  const std::string data = read_input_file(path, file.c_str(), std::size_t{1} << 30);
  int number = 0;
  std::size_t at = 0;
  while (at < data.size()) {
    std::size_t end = data.find('\n', at);
    if (end == std::string::npos) end = data.size();
    ++number;
    const std::vector<std::string> tokens = tokens_of(data.substr(at, end - at));
    if (!tokens.empty()) on_line(tokens, number);
    at = end + 1;
  }
}

// Sparse cotangent Laplacian (positive semi-definite form: L(i,i) = sum of weights, L(i,j) =
// -w_ij) with edge weights clamped below at 1e-3.
Eigen::SparseMatrix<double> clamped_cotangent_laplacian(const MatrixX3d& V, const MatrixX3i& F) {
  const int n = static_cast<int>(V.rows());
  std::vector<Eigen::Triplet<double>> half;  // (i < j) -> cot contributions
  half.reserve(static_cast<size_t>(F.rows()) * 3);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, (k + 1) % 3), j = F(f, (k + 2) % 3);
      if (i == j) continue;
      const Vector3d a = row3(V, i) - row3(V, F(f, k)), b = row3(V, j) - row3(V, F(f, k));
      const double s = a.cross(b).norm();
      const double cot = s > 0 ? a.dot(b) / s : 0.0;
      half.emplace_back(std::min(i, j), std::max(i, j), 0.5 * cot);
    }
  Eigen::SparseMatrix<double> W(n, n);
  W.setFromTriplets(half.begin(), half.end());  // sums both sides of each edge
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(W.nonZeros()) * 4);
  for (int c = 0; c < W.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(W, c); it; ++it) {
      const double w = std::max(it.value(), 1e-3);
      const int i = static_cast<int>(it.row()), j = static_cast<int>(it.col());
      t.emplace_back(i, j, -w);
      t.emplace_back(j, i, -w);
      t.emplace_back(i, i, w);
      t.emplace_back(j, j, w);
    }
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(t.begin(), t.end());
  return L;
}

// Biharmonic interpolation of the projected keys; rows of vertices it does not reach are zero.
MatrixX3d interpolated_key_vectors(const MatrixX3d& V, const MatrixX3i& F,
                                   const std::vector<KeyVector>& keys, const MatrixX3d& VN) {
  const int n = static_cast<int>(V.rows());
  MQ_CHECK(!keys.empty(), InvalidInput, "key vectors: no key vector given");
  std::vector<char> used(n, 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[F(f, k)] = 1;
  MatrixX3d X = MatrixX3d::Zero(n, 3);
  std::vector<int> key_of(n, -1);
  for (size_t i = 0; i < keys.size(); ++i) {
    const KeyVector& key = keys[i];
    MQ_CHECK(key.vertex >= 0 && key.vertex < n, InvalidInput, "key vector ", i, ": vertex ",
             key.vertex, " out of range [0, ", n, ")");
    MQ_CHECK(used[key.vertex], InvalidInput, "key vector ", i, ": vertex ", key.vertex,
             " is used by no face");
    MQ_CHECK(key.direction.allFinite() && key.direction.norm() > 0, InvalidInput, "key vector ", i,
             ": direction must be finite and non-zero");
    MQ_CHECK(key_of[key.vertex] < 0, InvalidInput, "key vector ", i, ": vertex ", key.vertex,
             " already has a key");
    const Vector3d t = tangent_part(key.direction.normalized(), row3(VN, key.vertex));
    MQ_CHECK(t.norm() > kParallel, InvalidInput, "key vector ", i, ": direction at vertex ",
             key.vertex, " is parallel to the surface normal");
    key_of[key.vertex] = static_cast<int>(i);
    X.row(key.vertex) = t.normalized().transpose();
  }
  // Vertices of components that hold a key are interpolated; the others stay zero.
  std::vector<int> face_component;
  const int nc = connected_components(F, n, face_component);
  std::vector<int> vertex_component(n, -1);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) vertex_component[F(f, k)] = face_component[f];
  std::vector<char> has_key(nc, 0);
  for (const KeyVector& key : keys) has_key[vertex_component[key.vertex]] = 1;
  std::vector<int> unknown(n, -1);
  int nu = 0;
  for (int v = 0; v < n; ++v)
    if (used[v] && key_of[v] < 0 && has_key[vertex_component[v]]) unknown[v] = nu++;
  if (nu == 0) return X;
  // Bilaplacian Q = L M^-1 L with the lumped (barycentric) mass matrix: unlike the Laplacian,
  // whose point constraints give spikes, it interpolates smoothly (C1) through the keys.
  const Eigen::SparseMatrix<double> L = clamped_cotangent_laplacian(V, F);
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd face_area = face_areas(V, F);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) mass(F(f, k)) += face_area(f) / 3.0;
  const double mean_mass = mass.sum() / std::max(1, static_cast<int>((mass.array() > 0).count()));
  for (int v = 0; v < n; ++v)  // zero-area fans: keep the system defined
    mass(v) = 1.0 / std::max(mass(v), 1e-12 * mean_mass);
  const Eigen::SparseMatrix<double> Q = L * mass.asDiagonal() * L;
  std::vector<Eigen::Triplet<double>> t;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nu, 3);
  for (int c = 0; c < Q.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Q, c); it; ++it) {
      const int i = static_cast<int>(it.row()), j = static_cast<int>(it.col());
      if (unknown[i] < 0) continue;
      if (unknown[j] >= 0)
        t.emplace_back(unknown[i], unknown[j], it.value());
      else if (key_of[j] >= 0)
        rhs.row(unknown[i]) -= it.value() * X.row(j);
    }
  Eigen::SparseMatrix<double> A(nu, nu);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  MQ_CHECK(solver.info() == Eigen::Success, SolverFailure,
           "key vectors: factorisation of the bilaplacian failed");
  const Eigen::MatrixXd x = solver.solve(rhs);
  MQ_CHECK(solver.info() == Eigen::Success && x.allFinite(), SolverFailure,
           "key vectors: the biharmonic solve failed");
  for (int v = 0; v < n; ++v)
    if (unknown[v] >= 0) X.row(v) = x.row(unknown[v]);
  return X;
}

MatrixX3d face_field_from_raw_vertex(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& X) {
  MatrixX3d raw(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f)
    raw.row(f) = (X.row(F(f, 0)) + X.row(F(f, 1)) + X.row(F(f, 2))) / 3.0;
  const double scale = X.rows() > 0 ? X.rowwise().norm().maxCoeff() : 0.0;
  return finish_field(V, F, face_normals(V, F), raw, scale);
}

}  // namespace

MatrixX3d tangent_field_from_direction(const MatrixX3d& V, const MatrixX3i& F,
                                       const Vector3d& direction) {
  check_mesh(V, F);
  MQ_CHECK(direction.allFinite() && direction.norm() > 0, InvalidInput,
           "tangent field: the direction must be finite and non-zero");
  const Vector3d d = direction.normalized();
  // A direction along every face's normal (0 0 1 over a base in the z = 0 plane) has no part
  // along the surface: the field would be the unguided one, silently (issue 28).
  const MatrixX3d N = face_normals(V, F);
  bool along_surface = false;
  for (int f = 0; f < F.rows() && !along_surface; ++f)
    along_surface = (d - d.dot(N.row(f).transpose()) * N.row(f).transpose()).norm() > 1e-3;
  MQ_CHECK(along_surface, InvalidInput, "the guidance direction (", direction.x(), " ",
           direction.y(), " ", direction.z(),
           ") is normal to the base everywhere, so it gives no direction along the surface; "
           "give one along the surface");
  MatrixX3d raw(F.rows(), 3);
  raw.rowwise() = d.transpose();
  return finish_field(V, F, N, raw, 1.0);
}

MatrixX3d read_vertex_vector_field(const std::string& path, int num_vertices) {
  MQ_CHECK(num_vertices >= 0, InvalidInput, "vector field: negative vertex count");
  MatrixX3d out(num_vertices, 3);
  int count = 0;
  for_each_data_line(path, "vector field", [&](const std::vector<std::string>& tok, int line) {
    MQ_CHECK(tok.size() == 3, InvalidInput, path, ":", line, ": expected \"x y z\", got ",
             tok.size(), " fields");
    MQ_CHECK(count < num_vertices, InvalidInput, path, ":", line, ": more vectors than the ",
             num_vertices, " vertices");
    for (int k = 0; k < 3; ++k) {
      double value = 0;
      MQ_CHECK(parse_double(tok[k], value), InvalidInput, path, ":", line,
               ": not a finite number: '", tok[k], "'");
      out(count, k) = value;
    }
    ++count;
  });
  MQ_CHECK(count == num_vertices, InvalidInput, path, ": ", count, " vectors for ", num_vertices,
           " vertices");
  return out;
}

MatrixX3d tangent_field_from_vertex_vectors(const MatrixX3d& V, const MatrixX3i& F,
                                            const MatrixX3d& vertex_vectors) {
  check_mesh(V, F);
  MQ_CHECK(vertex_vectors.rows() == V.rows(), InvalidInput,
           "tangent field: ", vertex_vectors.rows(), " vertex vectors for ", V.rows(), " vertices");
  MQ_CHECK(vertex_vectors.allFinite(), InvalidInput, "tangent field: non-finite vertex vector");
  // An all-zero field gives no direction anywhere; silently replacing it by the smooth default
  // would hide a broken export (issue 14).
  MQ_CHECK(vertex_vectors.size() == 0 || vertex_vectors.cwiseAbs().maxCoeff() > 0, InvalidInput,
           "the guidance field's vectors are all zero: no direction to follow");
  return face_field_from_raw_vertex(V, F, vertex_vectors);
}

std::vector<KeyVector> read_key_vectors(const std::string& path, int num_vertices) {
  std::vector<KeyVector> keys;
  std::vector<int> line_of(std::max(num_vertices, 0), 0);
  for_each_data_line(path, "key vector", [&](const std::vector<std::string>& tok, int line) {
    MQ_CHECK(tok.size() == 4, InvalidInput, path, ":", line,
             ": expected \"vertex_index x y z\", got ", tok.size(), " fields");
    long index = 0;
    MQ_CHECK(parse_int(tok[0], index), InvalidInput, path, ":", line, ": not a vertex index: '",
             tok[0], "'");
    MQ_CHECK(index >= 0 && index < num_vertices, InvalidInput, path, ":", line, ": vertex ", index,
             " out of range [0, ", num_vertices, ")");
    KeyVector key;
    key.vertex = static_cast<int>(index);
    for (int k = 0; k < 3; ++k)
      MQ_CHECK(parse_double(tok[k + 1], key.direction(k)), InvalidInput, path, ":", line,
               ": not a finite number: '", tok[k + 1], "'");
    MQ_CHECK(key.direction.norm() > 0, InvalidInput, path, ":", line, ": zero key vector");
    MQ_CHECK(line_of[key.vertex] == 0, InvalidInput, path, ":", line, ": vertex ", key.vertex,
             " already has a key (line ", line_of[key.vertex], ")");
    line_of[key.vertex] = line;
    keys.push_back(key);
  });
  return keys;
}

MatrixX3d vertex_field_from_key_vectors(const MatrixX3d& V, const MatrixX3i& F,
                                        const std::vector<KeyVector>& keys) {
  check_mesh(V, F);
  const MatrixX3d VN = vertex_normals(V, F);
  const MatrixX3d X = interpolated_key_vectors(V, F, keys, VN);
  const MatrixX3d fallback = vertex_tangent_field(V, F, face_field_from_raw_vertex(V, F, X));
  MatrixX3d out(V.rows(), 3);
  for (int v = 0; v < V.rows(); ++v) {
    const Vector3d t = tangent_part(row3(X, v), row3(VN, v));
    out.row(v) = (t.norm() > kParallel ? Vector3d(t / t.norm()) : row3(fallback, v)).transpose();
  }
  return out;
}

MatrixX3d tangent_field_from_key_vectors(const MatrixX3d& V, const MatrixX3i& F,
                                         const std::vector<KeyVector>& keys) {
  check_mesh(V, F);
  const MatrixX3d X = interpolated_key_vectors(V, F, keys, vertex_normals(V, F));
  return face_field_from_raw_vertex(V, F, X);
}

MatrixX3d smooth_tangent_field(const MatrixX3d& V, const MatrixX3i& F, int iterations) {
  check_mesh(V, F);
  MQ_CHECK(iterations >= 0, InvalidInput, "smooth tangent field: negative iteration count");
  const int nf = static_cast<int>(F.rows());
  if (nf == 0) return MatrixX3d(0, 3);
  const MatrixX3d N = face_normals(V, F);
  const Vector3d axis = Vector3d::Unit(axes_by_extent(V, F)[0]);
  MatrixX3d raw(nf, 3);
  raw.rowwise() = axis.transpose();
  MatrixX3d T = finish_field(V, F, N, raw, 1.0);
  const MatrixX3i TT = face_adjacency(edge_topology(F, static_cast<int>(V.rows())));
  MatrixX3d next(nf, 3);
  for (int it = 0; it < iterations; ++it) {
    for (int f = 0; f < nf; ++f) {
      const Vector3d n = row3(N, f);
      Vector3d sum = row3(T, f);
      for (int k = 0; k < 3; ++k)
        if (TT(f, k) >= 0) sum += row3(T, TT(f, k));
      const Vector3d t = tangent_part(sum, n);
      next.row(f) = (t.norm() > kParallel ? Vector3d(t / t.norm()) : row3(T, f)).transpose();
    }
    T.swap(next);
  }
  return T;
}

MatrixX3d vertex_tangent_field(const MatrixX3d& V, const MatrixX3i& F,
                               const MatrixX3d& face_field) {
  check_mesh(V, F);
  MQ_CHECK(face_field.rows() == F.rows(), InvalidInput, "vertex tangent field: ", face_field.rows(),
           " face vectors for ", F.rows(), " faces");
  const int n = static_cast<int>(V.rows());
  const MatrixX3d VN = vertex_normals(V, F);
  const Eigen::VectorXd A = face_areas(V, F);
  MatrixX3d sum = MatrixX3d::Zero(n, 3);
  std::vector<int> largest(n, -1);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = F(f, k);
      sum.row(v) += A(f) * face_field.row(f);
      if (largest[v] < 0 || A(f) > A(largest[v])) largest[v] = f;
    }
  MatrixX3d out = MatrixX3d::Zero(n, 3);
  for (int v = 0; v < n; ++v) {
    if (largest[v] < 0) continue;
    const Vector3d nv = row3(VN, v);
    Vector3d t = tangent_part(row3(sum, v), nv);
    if (t.norm() <= kParallel) t = tangent_part(row3(face_field, largest[v]), nv);
    if (t.norm() <= kParallel) t = axis_fallback({0, 1, 2}, nv);
    out.row(v) = t.normalized().transpose();
  }
  return out;
}

}  // namespace mq
