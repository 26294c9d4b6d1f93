#include "core/shell/shell_tetrahedra.h"

// The Debian libtet is built as a library; its header leaves the switch commented out, and
// without it the string overload of tetrahedralize() is not declared.
#ifndef TETLIBRARY
#define TETLIBRARY
#endif
#include <tetgen.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "core/common/errors.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

namespace {

void check_faces(const MatrixX3i& F, int n, const char* who) {
  MQ_CHECK(n >= 0, InvalidInput, who, ": negative vertex count");
  if (F.rows() == 0) return;
  MQ_CHECK(F.minCoeff() >= 0 && F.maxCoeff() < n, InvalidInput, who,
           ": face index out of range [0, ", n, ")");
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    MQ_CHECK(F(f, 0) != F(f, 1) && F(f, 1) != F(f, 2) && F(f, 2) != F(f, 0), InvalidInput, who,
             ": face ", f, " repeats a vertex");
}

void check_shell_input(const MatrixX3d& base_V, const MatrixX3d& offset_V, const MatrixX3i& F,
                       const char* who) {
  MQ_CHECK(base_V.rows() == offset_V.rows(), InvalidInput, who, ": ", base_V.rows(),
           " base vertices but ", offset_V.rows(), " offset vertices");
  MQ_CHECK(base_V.allFinite() && offset_V.allFinite(), InvalidInput, who,
           ": vertices contain NaN or infinite values");
  check_faces(F, static_cast<int>(base_V.rows()), who);
}

MatrixX3d stack(const MatrixX3d& A, const MatrixX3d& B) {
  MatrixX3d V(A.rows() + B.rows(), 3);
  V << A, B;
  return V;
}

// Positive-volume test with a scale-relative tolerance.
bool tet_is_positive(const MatrixX3d& V, const Eigen::RowVector4i& t, double* volume) {
  const Vector3d p[4] = {V.row(t(0)), V.row(t(1)), V.row(t(2)), V.row(t(3))};
  double l2 = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) l2 = std::max(l2, (p[i] - p[j]).squaredNorm());
  const double vol = tet_volume(p[0], p[1], p[2], p[3]);
  if (volume) *volume = vol;
  return vol > 1e-12 * l2 * std::sqrt(l2);
}

const char* tetgen_error_meaning(int code) {
  switch (code) {
    case 1:
      return "out of memory";
    case 2:
      return "internal error";
    case 3:
      return "self-intersection detected";
    case 4:
      return "very small input feature size";
    case 5:
      return "very small input feature size (close facets)";
    case 10:
      return "input error";
    default:
      return "unknown error";
  }
}

}  // namespace

TetIndices shell_tet_indices(const MatrixX3i& F, int num_base_vertices) {
  check_faces(F, num_base_vertices, "shell tetrahedra");
  const int n = num_base_vertices;
  TetIndices T(3 * F.rows(), 4);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    std::array<int, 3> v = {F(f, 0), F(f, 1), F(f, 2)};
    // Sorting three items: the permutation is odd iff it is a single transposition, i.e. the
    // sorted triple is not a rotation of the face's own (counter-clockwise) order.
    std::array<int, 3> s = v;
    std::sort(s.begin(), s.end());
    const bool even = (s == v) || (s == std::array<int, 3>{v[1], v[2], v[0]}) ||
                      (s == std::array<int, 3>{v[2], v[0], v[1]});
    const int rows[3][4] = {{s[0], s[1], s[2], n + s[0]},
                            {s[1], s[2], n + s[0], n + s[1]},
                            {s[2], n + s[0], n + s[1], n + s[2]}};
    for (int k = 0; k < 3; ++k) {
      T.row(3 * f + k) << rows[k][0], rows[k][1], rows[k][2], rows[k][3];
      if (!even) std::swap(T(3 * f + k, 0), T(3 * f + k, 1));
    }
  }
  return T;
}

TetMesh shell_tetrahedra(const MatrixX3d& base_V, const MatrixX3d& offset_V, const MatrixX3i& F) {
  check_shell_input(base_V, offset_V, F, "shell tetrahedra");
  TetMesh mesh;
  mesh.V = stack(base_V, offset_V);
  mesh.T = shell_tet_indices(F, static_cast<int>(base_V.rows()));
  for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
    double vol = 0.0;
    MQ_CHECK(tet_is_positive(mesh.V, mesh.T.row(t), &vol), TopologyError,
             "shell tetrahedra: the prism over face ", t / 3, " has an ",
             vol <= 0.0 ? "inverted" : "degenerate", " tet (volume ", vol,
             "): the offset surface is invalid there");
  }
  return mesh;
}

MatrixX3i shell_boundary_faces(const MatrixX3i& F, int num_base_vertices) {
  check_faces(F, num_base_vertices, "shell boundary");
  const int n = num_base_vertices;
  const EdgeTopology topo = edge_topology(F, n);
  std::vector<std::array<int, 3>> sides;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      if (!topo.is_boundary(topo.FE(f, k))) continue;
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      // Quad a b b' a' (outward: the face lies left of a -> b); diagonal from the larger
      // index's base vertex to the smaller one's offset, as in shell_tet_indices.
      if (a < b) {
        sides.push_back({a, b, n + a});
        sides.push_back({b, n + b, n + a});
      } else {
        sides.push_back({a, b, n + b});
        sides.push_back({a, n + b, n + a});
      }
    }
  MatrixX3i B(2 * F.rows() + static_cast<Eigen::Index>(sides.size()), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    B.row(f) << F(f, 0), F(f, 2), F(f, 1);
    B.row(F.rows() + f) = F.row(f).array() + n;
  }
  for (std::size_t i = 0; i < sides.size(); ++i)
    B.row(2 * F.rows() + static_cast<Eigen::Index>(i)) << sides[i][0], sides[i][1], sides[i][2];
  return B;
}

std::vector<int> tetgen_intersecting_faces(const MatrixX3d& V, const MatrixX3i& F) {
  MQ_CHECK(V.allFinite(), InvalidInput, "TetGen check: vertices contain NaN or infinite values");
  check_faces(F, static_cast<int>(V.rows()), "TetGen check");
  std::map<std::array<int, 3>, std::vector<int>> by_corners;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const double l2 =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    MQ_CHECK((b - a).cross(c - a).norm() > 1e-14 * l2 && l2 > 0, InvalidInput,
             "TetGen check: face ", f, " has zero area");
    std::array<int, 3> key = {F(f, 0), F(f, 1), F(f, 2)};
    std::sort(key.begin(), key.end());
    by_corners[key].push_back(static_cast<int>(f));
  }
  if (F.rows() == 0) return {};

  // tetgenio frees its arrays with delete[] in its destructor.
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(V.rows());
  in.pointlist = new REAL[3 * V.rows()];
  std::copy(V.data(), V.data() + V.size(), in.pointlist);
  in.numberoffacets = static_cast<int>(F.rows());
  in.facetlist = new tetgenio::facet[F.rows()];
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = F(f, k);
  }
  char switches[] = "pdQ";
  try {
    tetrahedralize(switches, &in, &out);
  } catch (int code) {
    MQ_THROW(SolverFailure, "TetGen failed with code ", code, " (", tetgen_error_meaning(code),
             ")");
  }

  // -d leaves the intersecting facets in out.trifacelist, as corner triples of input points.
  std::vector<int> result;
  for (int i = 0; i < out.numberoftrifaces; ++i) {
    std::array<int, 3> key = {out.trifacelist[3 * i], out.trifacelist[3 * i + 1],
                              out.trifacelist[3 * i + 2]};
    for (int& k : key) k -= out.firstnumber;
    std::sort(key.begin(), key.end());
    const auto it = by_corners.find(key);
    // TetGen merges coincident points, so a reported triple may name a twin of our corner.
    MQ_CHECK(it != by_corners.end(), InvalidInput, "TetGen check: intersecting face (", key[0], " ",
             key[1], " ", key[2], ") lies on coincident vertices");
    result.insert(result.end(), it->second.begin(), it->second.end());
  }
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

ShellValidation validate_shell(const MatrixX3d& base_V, const MatrixX3d& offset_V,
                               const MatrixX3i& F) {
  check_shell_input(base_V, offset_V, F, "validate shell");
  const int n = static_cast<int>(base_V.rows());
  const MatrixX3d V = stack(base_V, offset_V);
  const TetIndices T = shell_tet_indices(F, n);
  ShellValidation report;
  report.num_tets = static_cast<int>(T.rows());
  report.min_volume = T.rows() ? std::numeric_limits<double>::infinity() : 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    double vol = 0.0;
    if (!tet_is_positive(V, T.row(t), &vol)) ++report.num_nonpositive_tets;
    report.min_volume = std::min(report.min_volume, vol);
  }
  report.intersecting_boundary_faces = tetgen_intersecting_faces(V, shell_boundary_faces(F, n));
  return report;
}

}  // namespace mq
