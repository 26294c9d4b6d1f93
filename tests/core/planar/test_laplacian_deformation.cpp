#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/laplacian_deformation.h"
#include "tests/core/planar/cut_fixtures.h"
#include "tests/test_support.h"

namespace mq {
namespace {

double unit_random(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

Vector3d random_vector(std::mt19937_64& rng) {
  const double x = 2.0 * unit_random(rng) - 1.0;
  const double y = 2.0 * unit_random(rng) - 1.0;
  const double z = 2.0 * unit_random(rng) - 1.0;
  return Vector3d(x, y, z);
}

Vector3d row(const MatrixX3d& M, int i) { return M.row(i).transpose(); }

Vector3d face_point(const MatrixX3d& V, const MatrixX3i& F, int f, const Vector3d& w) {
  return w.x() * row(V, F(f, 0)) + w.y() * row(V, F(f, 1)) + w.z() * row(V, F(f, 2));
}

// Breadth-first hop distance from source along the edges of F (-1 when unreachable).
std::vector<int> hop_distance(const MatrixX3i& F, int n, int source) {
  const Adjacency adj = vertex_adjacency(F, n);
  std::vector<int> dist(n, -1), queue{source};
  dist[source] = 0;
  for (size_t q = 0; q < queue.size(); ++q)
    for (const int* j = adj.begin(queue[q]); j != adj.end(queue[q]); ++j)
      if (dist[*j] < 0) {
        dist[*j] = dist[queue[q]] + 1;
        queue.push_back(*j);
      }
  return dist;
}

// The reference: dense normal equations of Eqs. (5)/(6) for a single connected element.
MatrixX3d dense_solution(const MatrixX3d& V, const MatrixX3i& F,
                         const std::vector<LinearConstraint>& constraints, double mu) {
  const int n = static_cast<int>(V.rows());
  const Eigen::MatrixXd L = Eigen::MatrixXd(uniform_laplacian(F, n));
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(static_cast<int>(constraints.size()), n);
  Eigen::MatrixXd c(static_cast<int>(constraints.size()), 3);
  for (size_t i = 0; i < constraints.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      if (constraints[i].vertices[k] >= 0)
        C(i, constraints[i].vertices[k]) += constraints[i].weights[k];
    c.row(i) = constraints[i].target.transpose();
  }
  const Eigen::MatrixXd A = L.transpose() * L + mu * C.transpose() * C;
  const Eigen::MatrixXd b = L.transpose() * (L * V) + mu * C.transpose() * c;
  return A.ldlt().solve(b);
}

double energy(const LaplacianDeformer& d, const MatrixX3d& W,
              const std::vector<LinearConstraint>& constraints) {
  double e = (d.laplacian() * W - d.laplacian_coordinates()).squaredNorm();
  for (const LinearConstraint& c : constraints) {
    Vector3d p = Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (c.vertices[k] >= 0) p += c.weights[k] * row(W, c.vertices[k]);
    e += d.options().mu * (p - c.target).squaredNorm();
  }
  return e;
}

TriMesh load_torus576() { return read_mesh(test::shared_data("swatch/torus_576.off")); }

// The first `count` rings of the chain-mail swatch as separate elements.
std::vector<TriMesh> load_rings(int count) {
  const TriMesh mail = read_mesh(test::shared_data("swatch/chainmail3d_48rings_49k.obj"));
  std::vector<int> fc;
  const int nc = connected_components(mail.F, mail.num_vertices(), fc);
  const auto groups = component_faces(fc, nc);
  std::vector<TriMesh> rings;
  for (int c = 0; c < std::min(count, nc); ++c) rings.push_back(extract_faces(mail, groups[c]));
  return rings;
}

// Anchors every vertex at least `far` hops from source at its rest position and pulls source
// by d.
std::vector<LinearConstraint> anchored_pull(const TriMesh& m, int source, const Vector3d& d,
                                            int far) {
  const std::vector<int> dist = hop_distance(m.F, m.num_vertices(), source);
  std::vector<LinearConstraint> cs{LinearConstraint::point(source, row(m.V, source) + d)};
  for (int v = 0; v < m.num_vertices(); ++v)
    if (dist[v] >= far) cs.push_back(LinearConstraint::point(v, row(m.V, v)));
  return cs;
}

TEST(UniformLaplacian, RowsSumToZeroAndFlatInteriorVanishes) {
  const TriMesh g = test::plane_grid(2.0, 1.0, 8, 4);
  const int n = g.num_vertices() + 1;  // plus one isolated vertex
  const Eigen::SparseMatrix<double> L = uniform_laplacian(g.F, n);
  ASSERT_EQ(L.rows(), n);
  const Eigen::VectorXd sums = L * Eigen::VectorXd::Ones(n);
  EXPECT_LT(sums.cwiseAbs().maxCoeff(), 1e-14);
  for (int i = 0; i < g.num_vertices(); ++i) EXPECT_EQ(L.coeff(i, i), 1.0);
  EXPECT_EQ(Eigen::SparseVector<double>(L.row(n - 1)).nonZeros(), 0);

  MatrixX3d V(n, 3);
  V.topRows(g.num_vertices()) = g.V;
  V.row(n - 1) << 5, 5, 5;
  const MatrixX3d delta = L * V;
  const Adjacency adj = vertex_adjacency(g.F, n);
  int interior = 0, boundary = 0;
  for (int i = 0; i < g.num_vertices(); ++i) {
    const bool inner =
        g.V(i, 0) > 1e-9 && g.V(i, 0) < 2 - 1e-9 && g.V(i, 1) > 1e-9 && g.V(i, 1) < 1 - 1e-9;
    if (inner) {
      EXPECT_LT(delta.row(i).norm(), 1e-14) << "vertex " << i;
      EXPECT_EQ(adj.degree(i), 6);
      ++interior;
    } else {
      EXPECT_GT(delta.row(i).norm(), 1e-3) << "vertex " << i;
      ++boundary;
    }
  }
  EXPECT_EQ(interior, 7 * 3);
  EXPECT_EQ(boundary, 9 * 5 - 21);

  MatrixX3i bad = g.F;
  bad(3, 1) = n;
  EXPECT_THROW(uniform_laplacian(bad, n), InvalidInput);
  EXPECT_THROW(uniform_laplacian(g.F, -1), InvalidInput);
}

TEST(LaplacianDeformation, CurrentPositionsAreAFixedPoint) {
  for (const TriMesh& m : {test::torus(2.0, 0.5, 24, 12), load_torus576()}) {
    std::vector<LinearConstraint> cs;
    for (int v = 0; v < m.num_vertices(); v += 7)
      cs.push_back(LinearConstraint::point(v, row(m.V, v)));
    const Vector3d w(0.2, 0.3, 0.5);
    for (int f = 0; f < m.num_faces(); f += 11)
      cs.push_back(LinearConstraint::barycentric(m.F(f, 0), m.F(f, 1), m.F(f, 2), w,
                                                 face_point(m.V, m.F, f, w)));
    const MatrixX3d W = deform_element(m.V, m.F, cs);
    const double scale = m.V.cwiseAbs().maxCoeff();
    EXPECT_LT((W - m.V).cwiseAbs().maxCoeff(), 1e-9 * scale);
    // No constraint at all: nothing to solve, the element stays where it is.
    EXPECT_EQ((deform_element(m.V, m.F, {}) - m.V).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(LaplacianDeformation, MatchesDenseNormalEquations) {
  const TriMesh m = test::torus(2.0, 0.6, 10, 6);
  std::mt19937_64 rng(7);
  std::vector<LinearConstraint> cs;
  for (int i = 0; i < 8; ++i) {
    const int v = static_cast<int>(rng() % m.num_vertices());
    cs.push_back(LinearConstraint::point(v, row(m.V, v) + 0.3 * random_vector(rng)));
  }
  for (int i = 0; i < 6; ++i) {
    const int f = static_cast<int>(rng() % m.num_faces());
    const double a = unit_random(rng), b = (1 - a) * unit_random(rng);
    const Vector3d w(a, b, 1 - a - b);
    cs.push_back(LinearConstraint::barycentric(
        m.F(f, 0), m.F(f, 1), m.F(f, 2), w, face_point(m.V, m.F, f, w) + 0.3 * random_vector(rng)));
  }
  // Vertices far apart: outside the pattern of L^T L, so the solver extends it.
  cs.push_back(
      LinearConstraint::barycentric(0, 31, 47, Vector3d(0.5, 0.7, -0.2), Vector3d(1, 2, 0)));
  for (double mu : {1.0, 2.5, 40.0}) {
    DeformationOptions opt;
    opt.mu = mu;
    const MatrixX3d W = deform_element(m.V, m.F, cs, opt);
    const MatrixX3d ref = dense_solution(m.V, m.F, cs, mu);
    EXPECT_LT((W - ref).cwiseAbs().maxCoeff(), 1e-9) << "mu " << mu;
    // W is the minimiser: perturbing it raises the energy.
    const LaplacianDeformer d(m.V, m.F, opt);
    MatrixX3d P = W;
    P(5, 1) += 1e-3;
    EXPECT_GT(energy(d, P, cs), energy(d, W, cs));
  }
}

TEST(LaplacianDeformation, TranslatingTargetsTranslatesSolution) {
  const TriMesh m = load_torus576();
  const double h = mean_edge_length(m.V, m.F);
  std::vector<LinearConstraint> cs = anchored_pull(m, 10, Vector3d(0.4 * h, -0.2 * h, 0.3 * h), 6);
  cs.push_back(LinearConstraint::barycentric(m.F(3, 0), m.F(3, 1), m.F(3, 2),
                                             Vector3d(0.6, 0.3, 0.1), Vector3d(1, 2, 3)));
  const LaplacianDeformer d(m.V, m.F);
  const MatrixX3d W = d.solve(cs);
  const Vector3d shift(3.5 * h, -7.25 * h, 1.5 * h);
  for (LinearConstraint& c : cs) c.target += shift;
  const MatrixX3d Ws = d.solve(cs);
  const double scale = m.V.cwiseAbs().maxCoeff();
  for (int v = 0; v < m.num_vertices(); ++v)
    EXPECT_LT((row(Ws, v) - row(W, v) - shift).norm(), 1e-9 * scale) << "vertex " << v;
}

TEST(LaplacianDeformation, SingleConstraintTranslatesClosedElement) {
  // The Laplacian is translation invariant, so one constraint is met by a rigid translation.
  const TriMesh m = test::torus(2.0, 0.5, 16, 8);
  const Vector3d target(0.3, -1.0, 2.0);
  const MatrixX3d W = deform_element(m.V, m.F, {LinearConstraint::point(4, target)});
  const Vector3d d = target - row(m.V, 4);
  for (int v = 0; v < m.num_vertices(); ++v)
    EXPECT_LT((row(W, v) - row(m.V, v) - d).norm(), 1e-9) << "vertex " << v;
}

// Pulls one vertex with the far side anchored: the deformation is local and well behaved.
void check_local_pull(const TriMesh& m, int source) {
  SCOPED_TRACE(::testing::Message() << m.num_vertices() << " vertices, source " << source);
  const double h = mean_edge_length(m.V, m.F);
  const MatrixX3d N = vertex_normals(m.V, m.F);
  const Vector3d d = 0.3 * h * row(N, source);
  const std::vector<int> dist = hop_distance(m.F, m.num_vertices(), source);
  const int diameter = *std::max_element(dist.begin(), dist.end());
  ASSERT_GE(diameter, 6);
  const std::vector<LinearConstraint> cs = anchored_pull(m, source, d, (3 * diameter) / 4);
  const Vector3d target = cs[0].target;

  // The constraint residual shrinks as mu grows.
  double last = std::numeric_limits<double>::infinity();
  for (double mu : {0.1, 1.0, 10.0, 100.0}) {
    DeformationOptions opt;
    opt.mu = mu;
    const double residual = (row(deform_element(m.V, m.F, cs, opt), source) - target).norm();
    EXPECT_LT(residual, last) << "mu " << mu;
    last = residual;
  }
  EXPECT_LT(last, 0.05 * d.norm());

  const LaplacianDeformer deformer(m.V, m.F);
  const MatrixX3d W = deformer.solve(cs);
  // Approximately satisfied at mu = 1 and a better solution than not moving at all.
  EXPECT_LT((row(W, source) - target).norm(), 0.9 * d.norm());
  EXPECT_LT(energy(deformer, W, cs), energy(deformer, m.V, cs));
  EXPECT_GT((row(W, source) - row(m.V, source)).dot(d), 0.1 * d.squaredNorm());

  // Displacement decays with the hop distance from the pulled vertex (mean per ring), down to
  // almost nothing among the anchors.
  const int anchor_hops = (3 * diameter) / 4;
  std::vector<double> moved(diameter + 1, 0.0);
  std::vector<int> count(diameter + 1, 0);
  for (int v = 0; v < m.num_vertices(); ++v) {
    moved[dist[v]] += (row(W, v) - row(m.V, v)).norm();
    ++count[dist[v]];
  }
  for (int k = 0; k <= diameter; ++k) moved[k] /= count[k];
  for (int k = 1; k <= anchor_hops; ++k) EXPECT_LT(moved[k], moved[k - 1]) << "ring " << k;
  for (int k = anchor_hops; k <= diameter; ++k)
    EXPECT_LT(moved[k], 0.02 * moved[0]) << "ring " << k;

  // Laplacian coordinates change by a bounded amount.
  const MatrixX3d dL = deformer.laplacian() * W - deformer.laplacian_coordinates();
  EXPECT_LT(dL.rowwise().norm().maxCoeff(), d.norm());

  // Same connectivity; no face flips or collapses for a small pull.
  TriMesh out;
  out.V = W;
  out.F = m.F;
  const TopologyReport before = topology_report(m), after = topology_report(out);
  EXPECT_EQ(after.num_components, before.num_components);
  EXPECT_EQ(after.closed(), before.closed());
  EXPECT_EQ(after.manifold(), before.manifold());
  EXPECT_EQ(after.num_degenerate_faces, 0);
  const MatrixX3d FN0 = face_normals(m.V, m.F), FN1 = face_normals(W, m.F);
  for (int f = 0; f < m.num_faces(); ++f)
    EXPECT_GT(FN0.row(f).dot(FN1.row(f)), 0.8) << "face " << f;
}

TEST(LaplacianDeformation, LocalPullOnRealElements) {
  const TriMesh torus = load_torus576();
  ASSERT_EQ(torus.num_vertices(), 288);
  check_local_pull(torus, 0);
  check_local_pull(torus, 150);
  const std::vector<TriMesh> rings = load_rings(1);
  ASSERT_EQ(rings.size(), 1u);
  EXPECT_TRUE(topology_report(rings[0]).closed());
  check_local_pull(rings[0], 17);
}

// A long thread pulled at one end: the local solve agrees with the whole one within 1e-5 of an
// edge (the whole solve's motion decays about 14x every two rings past the anchors), leaves
// every vertex beyond rings + margin exactly in place and solves a fraction of the faces.
TEST(LaplacianDeformation, LocalSolveMatchesTheWholeSolve) {
  const TriMesh thread = test::tube(0.0, 20.0, 200, 12, 0.3, 0.0, true);
  const double edge = 0.1;
  std::vector<LinearConstraint> pull;
  for (int v = 0; v < thread.num_vertices(); ++v)
    if (std::abs(thread.V(v, 0) - 1.0) < 1e-9)
      pull.push_back(
          LinearConstraint::point(v, thread.V.row(v).transpose() + Vector3d(0.05, 0.2, 0.0)));
  ASSERT_EQ(pull.size(), 12u);
  std::vector<LinearConstraint> anchored = pull;
  const std::vector<LinearConstraint> anchors = anchor_far_vertices(thread.V, thread.F, pull, 8);
  anchored.insert(anchored.end(), anchors.begin(), anchors.end());
  const MatrixX3d whole = deform_element(thread.V, thread.F, anchored);
  const LocalDeformation local = deform_locally(thread.V, thread.F, pull, 8, 8);
  double largest = 0, motion = 0;
  for (int v = 0; v < thread.num_vertices(); ++v) {
    largest = std::max(largest, (whole.row(v) - local.V.row(v)).norm());
    motion = std::max(motion, (local.V.row(v) - thread.V.row(v)).norm());
    // The pull is at x = 1; 16 rings (1.6) on, nothing moves.
    if (thread.V(v, 0) > 2.65) {
      EXPECT_EQ(local.V.row(v), thread.V.row(v)) << v;
    }
  }
  EXPECT_GT(motion, 0.1);
  EXPECT_LT(largest, 1e-5 * edge);
  int moved = 0;
  for (const char m : local.moved_faces) moved += m;
  EXPECT_GT(moved, 0);
  EXPECT_LT(moved, thread.num_faces() / 5);
  // A margin of 0 differs more, but stays a local pull.
  const LocalDeformation tight = deform_locally(thread.V, thread.F, pull, 8, 0);
  EXPECT_GT((tight.V - whole).cwiseAbs().maxCoeff(), largest);
  EXPECT_THROW(deform_locally(thread.V, thread.F, pull, -1, 8), InvalidInput);
}

TEST(LaplacianDeformation, BarycentricUnitWeightEqualsPointForm) {
  const TriMesh m = load_torus576();
  const int f = 40, v = m.F(f, 1);
  std::vector<LinearConstraint> anchors = anchored_pull(m, v, Vector3d(0.5, 0.2, -0.3), 7);
  std::vector<LinearConstraint> bary = anchors;
  bary[0] = LinearConstraint::barycentric(m.F(f, 0), m.F(f, 1), m.F(f, 2), Vector3d(0, 1, 0),
                                          anchors[0].target);
  const MatrixX3d a = deform_element(m.V, m.F, anchors), b = deform_element(m.V, m.F, bary);
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT((a - m.V).cwiseAbs().maxCoeff(), 0.1);
}

TEST(LaplacianDeformation, FaceBarycenterConstraintsMoveTheFace) {
  // Eq. (6): constraints on points inside faces.
  const TriMesh m = load_torus576();
  const double h = mean_edge_length(m.V, m.F);
  const Vector3d third = Vector3d::Constant(1.0 / 3.0);
  const Vector3d d = 0.4 * h * row(face_normals(m.V, m.F), 100);
  const std::vector<int> dist = hop_distance(m.F, m.num_vertices(), m.F(100, 0));
  const int diameter = *std::max_element(dist.begin(), dist.end());
  std::vector<LinearConstraint> cs{LinearConstraint::barycentric(
      m.F(100, 0), m.F(100, 1), m.F(100, 2), third, face_point(m.V, m.F, 100, third) + d)};
  for (int f = 0; f < m.num_faces(); ++f)
    if (dist[m.F(f, 0)] >= (3 * diameter) / 4)
      cs.push_back(LinearConstraint::barycentric(m.F(f, 0), m.F(f, 1), m.F(f, 2), third,
                                                 face_point(m.V, m.F, f, third)));
  ASSERT_GT(cs.size(), 20u);
  for (double mu : {1.0, 100.0}) {
    DeformationOptions opt;
    opt.mu = mu;
    const MatrixX3d W = deform_element(m.V, m.F, cs, opt);
    const Vector3d moved = face_point(W, m.F, 100, third) - face_point(m.V, m.F, 100, third);
    EXPECT_GT(moved.dot(d) / d.squaredNorm(), mu > 10 ? 0.95 : 0.2) << "mu " << mu;
    EXPECT_LT((moved - d).norm(), mu > 10 ? 0.05 * d.norm() : 0.8 * d.norm()) << "mu " << mu;
    for (int k = 0; k < 3; ++k)  // the face's own corners follow it
      EXPECT_GT((row(W, m.F(100, k)) - row(m.V, m.F(100, k))).dot(d), 0.0);
  }
  // Every face barycenter shifted by d: the whole element translates by d.
  std::vector<LinearConstraint> all;
  for (int f = 0; f < m.num_faces(); f += 3)
    all.push_back(LinearConstraint::barycentric(m.F(f, 0), m.F(f, 1), m.F(f, 2), third,
                                                face_point(m.V, m.F, f, third) + d));
  const MatrixX3d W = deform_element(m.V, m.F, all);
  for (int v = 0; v < m.num_vertices(); ++v)
    EXPECT_LT((row(W, v) - row(m.V, v) - d).norm(), 1e-9 * m.V.cwiseAbs().maxCoeff());
}

TEST(LaplacianDeformation, ComponentsWithoutConstraintsKeepPositions) {
  TriMesh torus = test::torus(2.0, 0.5, 12, 6);
  TriMesh all = torus;
  TriMesh cube = test::unit_cube();
  cube.V.col(0).array() += 10.0;
  append_mesh(all, cube);
  const int isolated = all.num_vertices();
  all.V.conservativeResize(isolated + 1, 3);
  all.V.row(isolated) << -4, -4, -4;

  const std::vector<LinearConstraint> cs = anchored_pull(torus, 3, Vector3d(0.2, 0.1, 0.4), 5);
  const LaplacianDeformer d(all.V, all.F);
  EXPECT_EQ(d.num_components(), 3);
  const MatrixX3d W = d.solve(cs);
  EXPECT_EQ((W.bottomRows(9) - all.V.bottomRows(9)).cwiseAbs().maxCoeff(), 0.0);
  const MatrixX3d alone = deform_element(torus.V, torus.F, cs);
  EXPECT_LT((W.topRows(torus.num_vertices()) - alone).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_GT((alone - torus.V).cwiseAbs().maxCoeff(), 0.05);

  // A constrained isolated vertex (no Laplacian term) goes exactly to its target.
  std::vector<LinearConstraint> cs2 = cs;
  cs2.push_back(LinearConstraint::point(isolated, Vector3d(1, 2, 3)));
  const MatrixX3d W2 = d.solve(cs2);
  EXPECT_LT((row(W2, isolated) - Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_EQ((W2.middleRows(torus.num_vertices(), 8) - cube.V).cwiseAbs().maxCoeff(), 0.0);
}

TEST(LaplacianDeformation, DeformerReusesPrecomputation) {
  const TriMesh m = load_torus576();
  const LaplacianDeformer d(m.V, m.F);
  const auto c1 = anchored_pull(m, 5, Vector3d(1, 0, 0), 6);
  const auto c2 = anchored_pull(m, 200, Vector3d(0, -1, 0.5), 8);
  const MatrixX3d a1 = d.solve(c1), a2 = d.solve(c2), a3 = d.solve(c1);
  EXPECT_EQ((a1 - deform_element(m.V, m.F, c1)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((a2 - deform_element(m.V, m.F, c2)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((a1 - a3).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT((a1 - a2).cwiseAbs().maxCoeff(), 0.1);
}

TEST(LaplacianDeformation, ParallelJobsMatchSerialAndAreThreadCountIndependent) {
  const std::vector<TriMesh> rings = load_rings(6);
  ASSERT_EQ(rings.size(), 6u);
  std::vector<TriMesh> meshes = rings;
  meshes.push_back(load_torus576());
  meshes.push_back(test::torus(2.0, 0.5, 20, 10));
  std::mt19937_64 rng(1234);
  std::vector<DeformationJob> jobs;
  for (int j = 0; j < 24; ++j) {
    const TriMesh& m = meshes[j % meshes.size()];
    const double h = mean_edge_length(m.V, m.F);
    DeformationJob job{&m.V, &m.F, {}};
    for (int c = 0; c < 30; ++c) {
      const int f = static_cast<int>(rng() % m.num_faces());
      const double a = unit_random(rng), b = (1 - a) * unit_random(rng);
      const Vector3d w(a, b, 1 - a - b);
      job.constraints.push_back(
          LinearConstraint::barycentric(m.F(f, 0), m.F(f, 1), m.F(f, 2), w,
                                        face_point(m.V, m.F, f, w) + 0.3 * h * random_vector(rng)));
    }
    jobs.push_back(std::move(job));
  }
  std::vector<MatrixX3d> one, two;
  tbb::task_arena(1).execute([&] { one = deform_elements(jobs); });
  tbb::task_arena(2).execute([&] { two = deform_elements(jobs); });
  ASSERT_EQ(one.size(), jobs.size());
  ASSERT_EQ(two.size(), jobs.size());
  for (size_t j = 0; j < jobs.size(); ++j) {
    const MatrixX3d serial = deform_element(*jobs[j].V, *jobs[j].F, jobs[j].constraints);
    EXPECT_EQ((one[j] - serial).cwiseAbs().maxCoeff(), 0.0) << "job " << j;
    EXPECT_EQ((two[j] - serial).cwiseAbs().maxCoeff(), 0.0) << "job " << j;
    EXPECT_GT((serial - *jobs[j].V).cwiseAbs().maxCoeff(), 0.0) << "job " << j;
  }

  // Several failing jobs: the lowest-index error is reported whatever the thread count.
  jobs[5].constraints[2].target.y() = std::numeric_limits<double>::quiet_NaN();
  jobs[11].constraints[0].vertices[0] = 1 << 20;
  for (int threads : {1, 2}) {
    try {
      tbb::task_arena(threads).execute([&] { deform_elements(jobs); });
      ADD_FAILURE() << "no exception";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("constraint 2: target"), std::string::npos) << e.what();
    }
  }
  jobs[0].F = nullptr;
  EXPECT_THROW(deform_elements(jobs), InvalidInput);
}

// A topology shared between copies of an element (other positions, other constraints) gives
// bitwise the solves of a deformer built from scratch; the cache finds a topology only for
// exactly the same faces and vertex count; deform_elements with the cache matches without.
TEST(LaplacianDeformation, SharedTopologyGivesTheSameSolves) {
  const std::vector<TriMesh> rings = load_rings(2);
  ASSERT_EQ(rings.size(), 2u);
  const TriMesh torus = test::torus(2.0, 0.5, 20, 10);
  LaplacianTopologyCache cache;
  cache.add(rings[0].F, rings[0].num_vertices());
  cache.add(torus.F, torus.num_vertices());
  cache.add(torus.F, torus.num_vertices());  // held once
  EXPECT_EQ(cache.size(), 2u);
  ASSERT_TRUE(cache.find(torus.F, torus.num_vertices()));
  EXPECT_FALSE(cache.find(torus.F, torus.num_vertices() + 1));
  MatrixX3i flipped = torus.F;
  std::swap(flipped(3, 0), flipped(3, 1));
  EXPECT_FALSE(cache.find(flipped, torus.num_vertices()));

  std::mt19937_64 rng(99);
  std::vector<MatrixX3d> positions;
  std::vector<DeformationJob> jobs;
  // Copies of the torus moved and bent, and ring 1, whose topology is not cached.
  for (int j = 0; j < 6; ++j) {
    const TriMesh& m = j < 4 ? torus : rings[1];
    MatrixX3d V = m.V;
    V.rowwise() += Eigen::RowVector3d(3.0 * j, -1.0, 0.5);
    if (j % 2) V.col(2) += 0.1 * V.col(0).array().sin().matrix();
    positions.push_back(V);
  }
  for (int j = 0; j < 6; ++j) {
    const TriMesh& m = j < 4 ? torus : rings[1];
    DeformationJob job{&positions[static_cast<size_t>(j)], &m.F, {}};
    const double h = mean_edge_length(m.V, m.F);
    for (int c = 0; c < 20; ++c) {
      const int v = static_cast<int>(rng() % m.num_vertices());
      job.constraints.push_back(LinearConstraint::point(
          v, positions[static_cast<size_t>(j)].row(v).transpose() + 0.3 * h * random_vector(rng)));
    }
    jobs.push_back(std::move(job));
  }
  const auto shared = cache.find(torus.F, torus.num_vertices());
  for (int j = 0; j < 4; ++j) {
    const MatrixX3d fresh = deform_element(*jobs[j].V, *jobs[j].F, jobs[j].constraints);
    const MatrixX3d reused = LaplacianDeformer(shared, *jobs[j].V).solve(jobs[j].constraints);
    EXPECT_EQ((fresh - reused).cwiseAbs().maxCoeff(), 0.0) << "copy " << j;
    EXPECT_GT((fresh - *jobs[j].V).cwiseAbs().maxCoeff(), 0.0) << "copy " << j;
  }
  const std::vector<MatrixX3d> without = deform_elements(jobs),
                               with = deform_elements(jobs, {}, &cache);
  for (size_t j = 0; j < jobs.size(); ++j)
    EXPECT_EQ((without[j] - with[j]).cwiseAbs().maxCoeff(), 0.0) << "job " << j;
  EXPECT_THROW(LaplacianDeformer(shared, rings[1].V), InvalidInput);  // other vertex count
  EXPECT_THROW(LaplacianDeformer(nullptr, torus.V), InvalidInput);
}

TEST(LaplacianDeformation, InvalidInputThrows) {
  const TriMesh m = test::torus(2.0, 0.5, 8, 6);
  const int n = m.num_vertices();
  const Vector3d p(0, 0, 0);
  auto run = [&](const LinearConstraint& c) { return deform_element(m.V, m.F, {c}); };
  EXPECT_THROW(run(LinearConstraint::point(n, p)), InvalidInput);
  EXPECT_THROW(run(LinearConstraint::point(-2, p)), InvalidInput);
  EXPECT_THROW(run(LinearConstraint::point(-1, p)), InvalidInput);
  EXPECT_THROW(run(LinearConstraint::barycentric(0, 1, n + 5, Vector3d(0.5, 0.5, 0), p)),
               InvalidInput);
  EXPECT_THROW(run(LinearConstraint::point(0, Vector3d(0, std::nan(""), 0))), InvalidInput);
  EXPECT_THROW(run(LinearConstraint::point(0, Vector3d(0, 0, INFINITY))), InvalidInput);
  EXPECT_THROW(run(LinearConstraint::barycentric(0, 1, 2, Vector3d(0.5, 0.6, 0), p)),
               InvalidInput);  // weights do not sum to 1
  EXPECT_THROW(run(LinearConstraint::barycentric(0, 1, 2, Vector3d(std::nan(""), 0.5, 0.5), p)),
               InvalidInput);
  LinearConstraint orphan = LinearConstraint::point(0, p);
  orphan.weights = {{0.5, 0.5, 0.0}};  // weight on an unused slot
  EXPECT_THROW(run(orphan), InvalidInput);

  for (double mu : {0.0, -1.0, std::nan(""), double(INFINITY)}) {
    DeformationOptions opt;
    opt.mu = mu;
    EXPECT_THROW(deform_element(m.V, m.F, {LinearConstraint::point(0, p)}, opt), InvalidInput)
        << "mu " << mu;
  }
  MatrixX3d badV = m.V;
  badV(3, 2) = std::nan("");
  EXPECT_THROW(LaplacianDeformer(badV, m.F), InvalidInput);
  MatrixX3i badF = m.F;
  badF(0, 0) = n;
  EXPECT_THROW(LaplacianDeformer(m.V, badF), InvalidInput);

  // A constraint spanning two components would leave their relative translation free.
  TriMesh two = m;
  append_mesh(two, test::unit_cube());
  EXPECT_THROW(deform_element(two.V, two.F,
                              {LinearConstraint::barycentric(0, n, 1, Vector3d(0.5, 0.5, 0), p)}),
               InvalidInput);
}

}  // namespace
}  // namespace mq
