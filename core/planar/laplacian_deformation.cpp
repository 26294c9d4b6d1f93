#include "core/planar/laplacian_deformation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <exception>

#include "core/common/errors.h"
#include "core/common/fnv1a.h"
#include "core/mesh/mesh_topology.h"

namespace mq {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// Index into A.valuePtr() of the stored entry (row, col) of a compressed matrix, or -1.
Eigen::Index entry_index(const SpMat& A, int row, int col) {
  const int* first = A.innerIndexPtr() + A.outerIndexPtr()[col];
  const int* last = A.innerIndexPtr() + A.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(first, last, row);
  if (it == last || *it != row) return -1;
  return it - A.innerIndexPtr();
}

// Connected components of the graph whose edges are the off-diagonal entries of the symmetric
// pattern of L; they are exactly the blocks of the null space of L (constants per component).
int laplacian_components(const SpMat& L, std::vector<int>& component) {
  const int n = static_cast<int>(L.rows());
  component.assign(n, -1);
  std::vector<int> stack;
  int count = 0;
  for (int s = 0; s < n; ++s) {
    if (component[s] >= 0) continue;
    component[s] = count;
    stack.push_back(s);
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (SpMat::InnerIterator it(L, v); it; ++it) {
        const int u = static_cast<int>(it.row());
        if (component[u] < 0) {
          component[u] = count;
          stack.push_back(u);
        }
      }
    }
    ++count;
  }
  return count;
}

// A constraint reduced to its vertices with non-zero weight.
struct ActiveTerms {
  int count = 0;
  std::array<int, 3> vertex{};
  std::array<double, 3> weight{};
};

ActiveTerms validate_constraint(const LinearConstraint& c, size_t index,
                                const std::vector<int>& component) {
  const int n = static_cast<int>(component.size());
  ActiveTerms terms;
  double sum = 0.0;
  bool any_vertex = false;
  for (int k = 0; k < 3; ++k) {
    const int v = c.vertices[k];
    const double w = c.weights[k];
    MQ_CHECK(std::isfinite(w), InvalidInput, "constraint ", index, ": weight ", k,
             " is not finite");
    if (v == -1) {
      MQ_CHECK(w == 0.0, InvalidInput, "constraint ", index, ": weight ", k,
               " is non-zero but has no vertex");
      continue;
    }
    MQ_CHECK(v >= 0 && v < n, InvalidInput, "constraint ", index, " references vertex ", v,
             " but the element has ", n, " vertices");
    any_vertex = true;
    sum += w;
    if (w == 0.0) continue;
    terms.vertex[terms.count] = v;
    terms.weight[terms.count] = w;
    ++terms.count;
  }
  MQ_CHECK(any_vertex, InvalidInput, "constraint ", index, " references no vertex");
  MQ_CHECK(std::abs(sum - 1.0) <= 1e-6, InvalidInput, "constraint ", index, ": weights sum to ",
           sum, " instead of 1");
  MQ_CHECK(c.target.allFinite(), InvalidInput, "constraint ", index, ": target is not finite");
  for (int k = 1; k < terms.count; ++k)
    MQ_CHECK(component[terms.vertex[k]] == component[terms.vertex[0]], InvalidInput, "constraint ",
             index, " links vertices ", terms.vertex[0], " and ", terms.vertex[k],
             " of different connected components");
  return terms;
}

}  // namespace

SpMat uniform_laplacian(const MatrixX3i& F, int num_vertices) {
  MQ_CHECK(num_vertices >= 0, InvalidInput, "negative vertex count ", num_vertices);
  const Adjacency adj = vertex_adjacency(F, num_vertices);  // checks the indices
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(adj.indices.size() + static_cast<size_t>(num_vertices));
  for (int i = 0; i < num_vertices; ++i) {
    const int degree = adj.degree(i);
    if (degree == 0) continue;
    triplets.emplace_back(i, i, 1.0);
    const double w = -1.0 / degree;
    for (const int* j = adj.begin(i); j != adj.end(i); ++j) triplets.emplace_back(i, *j, w);
  }
  SpMat L(num_vertices, num_vertices);
  L.setFromTriplets(triplets.begin(), triplets.end());
  L.makeCompressed();
  return L;
}

LaplacianTopology::LaplacianTopology(const MatrixX3i& F, int num_vertices) : F_(F) {
  const int n = num_vertices;
  L_ = uniform_laplacian(F, n);  // checks n and the indices
  num_components_ = laplacian_components(L_, component_);
  perm_.resize(n);
  if (n == 0) return;

  // Pattern of the normal equations of Eq. (5): L^T L with every diagonal entry stored (zero
  // rows of isolated vertices included), so that constraints on single vertices and on faces
  // only change values, never the pattern.
  SpMat identity(n, n);
  identity.setIdentity();
  const SpMat Lt = L_.transpose();
  SpMat Q = Lt * L_ + 0.0 * identity;
  Q.makeCompressed();

  // One fill-reducing ordering for all later factorisations.
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> Pinv;
  Eigen::AMDOrdering<int> amd;
  amd(Q, Pinv);
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P = Pinv.inverse();
  for (int i = 0; i < n; ++i) perm_[i] = P.indices()(i);
  system_.resize(n, n);
  system_.selfadjointView<Eigen::Upper>() = Q.selfadjointView<Eigen::Upper>().twistedBy(P);
  system_.makeCompressed();
}

namespace {

std::uint64_t faces_hash(const MatrixX3i& F, int num_vertices) {
  std::uint64_t h = kFnv1aOffset;
  const Eigen::Index rows = F.rows();
  fnv1a(h, &num_vertices, sizeof num_vertices);
  fnv1a(h, &rows, sizeof rows);
  fnv1a(h, F.data(), sizeof(int) * static_cast<std::size_t>(F.size()));
  return h;
}

}  // namespace

void LaplacianTopologyCache::add(const MatrixX3i& F, int num_vertices) {
  if (find(F, num_vertices)) return;
  by_hash_[faces_hash(F, num_vertices)].push_back(
      std::make_shared<const LaplacianTopology>(F, num_vertices));
}

std::size_t LaplacianTopologyCache::size() const {
  std::size_t n = 0;
  for (const auto& bucket : by_hash_) n += bucket.second.size();
  return n;
}

std::shared_ptr<const LaplacianTopology> LaplacianTopologyCache::find(const MatrixX3i& F,
                                                                      int num_vertices) const {
  const auto it = by_hash_.find(faces_hash(F, num_vertices));
  if (it == by_hash_.end()) return nullptr;
  for (const auto& t : it->second)
    if (t->num_vertices() == num_vertices && t->faces() == F) return t;
  return nullptr;
}

LaplacianDeformer::LaplacianDeformer(const MatrixX3d& V, const MatrixX3i& F,
                                     const DeformationOptions& options)
    : V_(V), options_(options) {
  MQ_CHECK(std::isfinite(options.mu) && options.mu > 0.0, InvalidInput,
           "deformation weight mu must be positive and finite, got ", options.mu);
  MQ_CHECK(V.allFinite(), InvalidInput, "element vertex positions are not finite");
  topology_ = std::make_shared<const LaplacianTopology>(F, static_cast<int>(V.rows()));
  init_values();
}

LaplacianDeformer::LaplacianDeformer(std::shared_ptr<const LaplacianTopology> topology,
                                     const MatrixX3d& V, const DeformationOptions& options)
    : topology_(std::move(topology)), V_(V), options_(options) {
  MQ_CHECK(topology_, InvalidInput, "Laplacian deformer: null topology");
  MQ_CHECK(V.rows() == topology_->num_vertices(), InvalidInput, "Laplacian deformer: ", V.rows(),
           " positions for a topology of ", topology_->num_vertices(), " vertices");
  MQ_CHECK(std::isfinite(options.mu) && options.mu > 0.0, InvalidInput,
           "deformation weight mu must be positive and finite, got ", options.mu);
  MQ_CHECK(V.allFinite(), InvalidInput, "element vertex positions are not finite");
  init_values();
}

void LaplacianDeformer::init_values() {
  const SpMat& L = topology_->laplacian();
  const std::vector<int>& perm = topology_->permutation();
  delta_ = L * V_;
  const int n = num_vertices();
  if (n == 0) return;
  const SpMat Lt = L.transpose();
  const Eigen::MatrixXd b = Lt * delta_;
  rhs_.resize(n, 3);
  for (int i = 0; i < n; ++i) rhs_.row(perm[i]) = b.row(i);
}

MatrixX3d LaplacianDeformer::solve(const std::vector<LinearConstraint>& constraints) const {
  const int n = num_vertices();
  const double mu = options_.mu;
  const std::vector<int>& component = topology_->vertex_components();
  const std::vector<int>& perm = topology_->permutation();

  std::vector<ActiveTerms> terms(constraints.size());
  std::vector<char> constrained(topology_->num_components(), 0);
  for (size_t c = 0; c < constraints.size(); ++c) {
    terms[c] = validate_constraint(constraints[c], c, component);
    constrained[component[terms[c].vertex[0]]] = 1;
  }
  if (std::find(constrained.begin(), constrained.end(), 1) == constrained.end()) return V_;

  // Normal equations (L^T L + mu C^T C) W = L^T delta + mu C^T c, in the permuted numbering.
  SpMat A = topology_->permuted_normal_matrix();
  Eigen::MatrixXd B = rhs_;

  // Constraints between vertices not coupled by L^T L (not face-adjacent) extend the pattern.
  std::vector<Eigen::Triplet<double>> extra;
  for (const ActiveTerms& t : terms)
    for (int k = 0; k < t.count; ++k)
      for (int l = 0; l < t.count; ++l) {
        const int r = perm[t.vertex[k]], s = perm[t.vertex[l]];
        if (r <= s && entry_index(A, r, s) < 0) extra.emplace_back(r, s, 0.0);
      }
  if (!extra.empty()) {
    for (int col = 0; col < n; ++col)
      for (SpMat::InnerIterator it(A, col); it; ++it)
        extra.emplace_back(static_cast<int>(it.row()), col, it.value());
    A.setFromTriplets(extra.begin(), extra.end());  // duplicates of new entries add zeros
    A.makeCompressed();
  }

  double* values = A.valuePtr();
  for (size_t c = 0; c < constraints.size(); ++c) {
    const ActiveTerms& t = terms[c];
    for (int k = 0; k < t.count; ++k) {
      const int r = perm[t.vertex[k]];
      B.row(r) += (mu * t.weight[k]) * constraints[c].target.transpose();
      for (int l = 0; l < t.count; ++l) {
        const int s = perm[t.vertex[l]];
        if (r > s) continue;  // upper triangle; r == s is reached from both orders
        const Eigen::Index e = entry_index(A, r, s);
        MQ_ASSERT(e >= 0);
        values[e] += mu * t.weight[k] * t.weight[l];
      }
    }
  }

  // Components without constraints are excluded: identity rows pin them to their positions.
  // L^T L couples only vertices of one component, so zeroing their columns clears them fully.
  for (int i = 0; i < n; ++i) {
    if (constrained[component[i]]) continue;
    const int col = perm[i];
    for (Eigen::Index e = A.outerIndexPtr()[col]; e < A.outerIndexPtr()[col + 1]; ++e)
      values[e] = A.innerIndexPtr()[e] == col ? 1.0 : 0.0;
    B.row(col) = V_.row(i);
  }

  Eigen::SimplicialLDLT<SpMat, Eigen::Upper, Eigen::NaturalOrdering<int>> ldlt(A);
  MQ_CHECK(ldlt.info() == Eigen::Success, SolverFailure,
           "Laplacian deformation: factorisation of the normal equations failed (", n,
           " vertices, ", constraints.size(), " constraints)");
  MQ_CHECK(ldlt.vectorD().allFinite() && ldlt.vectorD().minCoeff() > 0.0, SolverFailure,
           "Laplacian deformation: normal equations are not positive definite (", n, " vertices, ",
           constraints.size(), " constraints)");
  const Eigen::MatrixXd X = ldlt.solve(B);
  MQ_CHECK(ldlt.info() == Eigen::Success && X.allFinite(), SolverFailure,
           "Laplacian deformation: back substitution failed (", n, " vertices)");

  MatrixX3d W(n, 3);
  for (int i = 0; i < n; ++i) {
    if (constrained[component[i]])
      W.row(i) = X.row(perm[i]);
    else
      W.row(i) = V_.row(i);
  }
  return W;
}

MatrixX3d deform_element(const MatrixX3d& V, const MatrixX3i& F,
                         const std::vector<LinearConstraint>& constraints,
                         const DeformationOptions& options) {
  return LaplacianDeformer(V, F, options).solve(constraints);
}

namespace {

// The element's topology when `topologies` (optional) holds it, else nullptr.
std::shared_ptr<const LaplacianTopology> cached_topology(const MatrixX3i& F, int num_vertices,
                                                         const LaplacianTopologyCache* topologies) {
  return topologies ? topologies->find(F, num_vertices) : nullptr;
}

// deform_element, on the topology `known` when given (cached_topology).
MatrixX3d solve_whole(const MatrixX3d& V, const MatrixX3i& F,
                      const std::vector<LinearConstraint>& constraints,
                      const DeformationOptions& options,
                      std::shared_ptr<const LaplacianTopology> known) {
  return known ? LaplacianDeformer(std::move(known), V, options).solve(constraints)
               : deform_element(V, F, constraints, options);
}

}  // namespace

std::vector<MatrixX3d> deform_elements(const std::vector<DeformationJob>& jobs,
                                       const DeformationOptions& options,
                                       const LaplacianTopologyCache* topologies) {
  for (size_t j = 0; j < jobs.size(); ++j)
    MQ_CHECK(jobs[j].V && jobs[j].F, InvalidInput, "deformation job ", j,
             " has no vertices or faces");
  std::vector<MatrixX3d> results(jobs.size());
  std::vector<std::exception_ptr> errors(jobs.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, jobs.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t j = range.begin(); j != range.end(); ++j) {
          try {
            const DeformationJob& job = jobs[j];
            results[j] = job.local_rings >= 0
                             ? deform_locally(*job.V, *job.F, job.constraints, job.local_rings,
                                              job.local_margin, options, topologies)
                                   .V
                             : solve_whole(*job.V, *job.F, job.constraints, options,
                                           cached_topology(*job.F, static_cast<int>(job.V->rows()),
                                                           topologies));
          } catch (...) {
            errors[j] = std::current_exception();
          }
        }
      });
  // The lowest-index failure, whatever the scheduling.
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  return results;
}

}  // namespace mq

namespace mq {

namespace {

// Hops (1-ring edges) from the vertices the constraints involve; -1 where none reaches.
std::vector<int> constraint_depth(const MatrixX3i& F, int nv,
                                  const std::vector<LinearConstraint>& constraints) {
  const Adjacency adj = vertex_adjacency(F, nv);
  std::vector<int> depth(nv, -1), queue;
  for (const LinearConstraint& c : constraints)
    for (int k = 0; k < 3; ++k) {
      const int v = c.vertices[k];
      if (v >= 0 && v < nv && depth[v] < 0) {
        depth[v] = 0;
        queue.push_back(v);
      }
    }
  for (size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head];
    for (const int* w = adj.begin(v); w != adj.end(v); ++w)
      if (depth[*w] < 0) {
        depth[*w] = depth[v] + 1;
        queue.push_back(*w);
      }
  }
  return depth;
}

}  // namespace

std::vector<LinearConstraint> anchor_far_vertices(const MatrixX3d& V, const MatrixX3i& F,
                                                  const std::vector<LinearConstraint>& constraints,
                                                  int rings) {
  const std::vector<int> depth = constraint_depth(F, static_cast<int>(V.rows()), constraints);
  std::vector<LinearConstraint> anchors;
  for (int v = 0; v < V.rows(); ++v)
    if (depth[v] > rings) anchors.push_back(LinearConstraint::point(v, V.row(v).transpose()));
  return anchors;
}

LocalDeformation deform_locally(const MatrixX3d& V, const MatrixX3i& F,
                                const std::vector<LinearConstraint>& constraints, int rings,
                                int margin, const DeformationOptions& options,
                                const LaplacianTopologyCache* topologies) {
  MQ_CHECK(rings >= 0 && margin >= 0, InvalidInput, "local deformation: rings (", rings,
           ") and margin (", margin, ") must be >= 0");
  const int nv = static_cast<int>(V.rows());
  const std::vector<int> depth = constraint_depth(F, nv, constraints);
  const int reach = rings + margin;
  const std::shared_ptr<const LaplacianTopology> known = cached_topology(F, nv, topologies);
  // The whole solve, as anchor_far_vertices and deform_element give it.
  const auto whole = [&] {
    std::vector<LinearConstraint> all = constraints;
    for (int v = 0; v < nv; ++v)
      if (depth[v] > rings) all.push_back(LinearConstraint::point(v, V.row(v).transpose()));
    return LocalDeformation{solve_whole(V, F, all, options, known), std::vector<char>(F.rows(), 1)};
  };
  // Wholly within reach (a compact element), or with a cached topology (a swatch element as
  // placed, whose cached solve costs less than a local one analysed afresh): solved whole.
  if (known || std::none_of(depth.begin(), depth.end(), [&](int d) { return d > reach; }))
    return whole();
  // The faces within reach, and their vertices renumbered.
  std::vector<int> local(nv, -1), global;
  std::vector<int> faces;
  for (int f = 0; f < F.rows(); ++f) {
    bool near = true;
    for (int k = 0; k < 3; ++k) near = near && depth[F(f, k)] >= 0 && depth[F(f, k)] <= reach;
    if (!near) continue;
    faces.push_back(f);
    for (int k = 0; k < 3; ++k)
      if (local[F(f, k)] < 0) {
        local[F(f, k)] = static_cast<int>(global.size());
        global.push_back(F(f, k));
      }
  }
  std::vector<LinearConstraint> cs;
  cs.reserve(constraints.size() + global.size());
  for (LinearConstraint c : constraints) {
    for (int k = 0; k < 3; ++k) {
      if (c.vertices[k] < 0) continue;
      MQ_CHECK(c.vertices[k] < nv, InvalidInput, "local deformation: constraint vertex ",
               c.vertices[k], " out of range [0, ", nv, ")");
      c.vertices[k] = local[c.vertices[k]];
      // A constrained vertex in no face within reach (an isolated one, or reach 0): solved whole.
      if (c.vertices[k] < 0) return whole();
    }
    cs.push_back(c);
  }
  MatrixX3d localV(global.size(), 3);
  for (size_t i = 0; i < global.size(); ++i) {
    localV.row(i) = V.row(global[i]);
    if (depth[global[i]] > rings)
      cs.push_back(LinearConstraint::point(static_cast<int>(i), V.row(global[i]).transpose()));
  }
  MatrixX3i localF(faces.size(), 3);
  for (size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) localF(i, k) = local[F(faces[i], k)];
  const MatrixX3d solved = deform_element(localV, localF, cs, options);
  LocalDeformation result{V, std::vector<char>(F.rows(), 0)};
  for (size_t i = 0; i < global.size(); ++i) result.V.row(global[i]) = solved.row(i);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) result.moved_faces[f] |= local[F(f, k)] >= 0;
  return result;
}

}  // namespace mq
