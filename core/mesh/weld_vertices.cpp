#include "core/mesh/weld_vertices.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

#include "core/common/errors.h"

namespace mq {

TriMesh weld_vertices(const TriMesh& mesh, int* merged, std::vector<int>* source) {
  MQ_CHECK(mesh.V.allFinite(), InvalidInput, "weld_vertices: non-finite vertex position");
  const int nv = mesh.num_vertices();
  auto key = [&mesh](int v) {
    // +0.0 == -0.0 for the comparison, as for the positions themselves.
    return std::array<double, 3>{mesh.V(v, 0) + 0.0, mesh.V(v, 1) + 0.0, mesh.V(v, 2) + 0.0};
  };
  std::vector<int> order(static_cast<size_t>(nv));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  // Each vertex's representative: the lowest index at its position (stable sort keeps it first).
  std::vector<int> representative(static_cast<size_t>(nv));
  for (size_t i = 0; i < order.size(); ++i)
    representative[order[i]] =
        i > 0 && key(order[i]) == key(order[i - 1]) ? representative[order[i - 1]] : order[i];
  std::vector<int> new_index(static_cast<size_t>(nv), -1);
  int count = 0;
  for (int v = 0; v < nv; ++v)
    if (representative[v] == v) new_index[v] = count++;
  if (merged) *merged = nv - count;
  if (source) {
    source->clear();
    for (int v = 0; v < nv; ++v)
      if (new_index[v] >= 0) source->push_back(v);
  }
  if (count == nv) return mesh;
  TriMesh out;
  out.V.resize(count, 3);
  for (int v = 0; v < nv; ++v)
    if (new_index[v] >= 0) out.V.row(new_index[v]) = mesh.V.row(v);
  out.F.resize(mesh.F.rows(), 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) out.F(f, k) = new_index[representative[mesh.F(f, k)]];
  return out;
}

}  // namespace mq
