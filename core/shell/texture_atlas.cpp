#include "core/shell/texture_atlas.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/mesh_topology.h"
#include "core/surface/lscm.h"

namespace mq {

namespace {

// Grows one chart from `seed` over faces not yet in a chart (chart[f] == -1), at most `budget`
// faces, keeping it a disk: a face joins when it shares exactly one edge with the chart and
// brings a vertex not yet in it, or shares exactly two edges (closing a notch).
std::vector<int> grow_chart(int seed, int id, int budget, const MatrixX3i& F, const MatrixX3d& FN,
                            const MatrixX3i& TT, double cone_cosine, std::vector<int>& chart,
                            std::vector<int>& vertex_mark, int& stamp) {
  ++stamp;  // vertex_mark[v] == stamp: v is in the chart being grown
  std::vector<int> faces;
  const Vector3d n0 = FN.row(seed);
  using Item = std::pair<double, int>;  // (-cosine, face): closest normals first, then face id
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  auto add = [&](int f) {
    chart[f] = id;
    faces.push_back(f);
    for (int k = 0; k < 3; ++k) vertex_mark[F(f, k)] = stamp;
    for (int k = 0; k < 3; ++k) {
      const int g = TT(f, k);
      if (g >= 0 && chart[g] == -1) queue.push({-n0.dot(FN.row(g)), g});
    }
  };
  add(seed);
  while (!queue.empty() && static_cast<int>(faces.size()) < budget) {
    const auto [neg_cos, f] = queue.top();
    queue.pop();
    if (chart[f] != -1 || -neg_cos < cone_cosine) continue;
    int shared = 0;
    for (int k = 0; k < 3; ++k) {
      const int g = TT(f, k);
      if (g >= 0 && chart[g] == id) ++shared;
    }
    int new_vertices = 0;
    for (int k = 0; k < 3; ++k) new_vertices += vertex_mark[F(f, k)] != stamp;
    const bool disk = (shared == 1 && new_vertices == 1) || (shared == 2 && new_vertices == 0);
    if (disk) add(f);
  }
  return faces;
}

struct Chart {
  std::vector<int> faces;
  std::vector<int> vertices;  // base vertex of each local vertex
  MatrixX2d uv;               // local UV
  MatrixX3i local_F;
};

bool flatten(const MatrixX3d& V, const MatrixX3i& F, Chart& c, double max_distortion) {
  TriMesh sub;
  sub.V = V;
  sub.F = F;
  TriMesh patch = extract_faces(sub, c.faces, &c.vertices);
  c.local_F = patch.F;
  if (c.faces.size() == 1) {
    // A single triangle: its isometric layout.
    const Vector3d a = patch.V.row(0), b = patch.V.row(1), p = patch.V.row(2);
    const Vector3d e = b - a;
    const double len = e.norm();
    const Vector3d x = e / len;
    const Vector3d q = p - a;
    c.uv.resize(3, 2);
    c.uv << 0, 0, len, 0, q.dot(x), (q - q.dot(x) * x).norm();
    return true;
  }
  try {
    c.uv = lscm(patch.V, patch.F);
  } catch (const TopologyError&) {
    return false;
  } catch (const SolverFailure&) {
    return false;
  }
  if (!c.uv.allFinite() || count_flipped(patch.F, c.uv) > 0) return false;
  const Eigen::VectorXd d = face_area_distortion(patch.V, patch.F, c.uv);
  if (!(d.maxCoeff() <= max_distortion)) return false;
  // No flips still allows the boundary to wrap over the chart: check global overlap.
  TextureAtlas single;
  single.UV = c.uv;
  single.FUV = patch.F;
  return count_uv_overlaps(single) == 0;
}

double tri_area2(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

void validate_atlas_input(const MatrixX3d& V, const MatrixX3i& F,
                          const TextureAtlasOptions& options) {
  MQ_CHECK(options.cone_cosine > -1.0 && options.cone_cosine < 1.0, InvalidInput,
           "texture atlas: cone_cosine must lie in (-1, 1), got ", options.cone_cosine);
  MQ_CHECK(options.max_area_distortion >= 1.0, InvalidInput,
           "texture atlas: max_area_distortion must be >= 1, got ", options.max_area_distortion);
  MQ_CHECK(options.max_chart_faces >= 1, InvalidInput,
           "texture atlas: max_chart_faces must be >= 1");
  MQ_CHECK(options.gutter >= 0.0 && std::isfinite(options.gutter), InvalidInput,
           "texture atlas: gutter must be finite and >= 0");
  MQ_CHECK(F.rows() > 0, InvalidInput, "texture atlas: the mesh has no faces");
  MQ_CHECK(V.allFinite(), InvalidInput, "texture atlas: vertices contain NaN or infinite values");
}

// Charts grown from each face not yet in one, by a work list of (seed, budget): a chart that
// fails to flatten is released and its faces re-seeded smaller. chart: each face's chart.
std::vector<Chart> grow_charts(const MatrixX3d& V, const MatrixX3i& F, const EdgeTopology& topo,
                               const TextureAtlasOptions& options, std::vector<int>& chart) {
  const int n = static_cast<int>(V.rows());
  const int nf = static_cast<int>(F.rows());
  const MatrixX3d FN = face_normals(V, F);
  const MatrixX3i TT = face_adjacency(topo);
  chart.assign(static_cast<size_t>(nf), -1);
  std::vector<int> vertex_mark(n, 0);
  int stamp = 0;
  std::vector<Chart> charts;
  for (int seed = 0; seed < nf; ++seed) {
    if (chart[seed] != -1) continue;
    int budget = options.max_chart_faces;
    for (;;) {
      const int id = static_cast<int>(charts.size());
      Chart c;
      c.faces =
          grow_chart(seed, id, budget, F, FN, TT, options.cone_cosine, chart, vertex_mark, stamp);
      std::sort(c.faces.begin(), c.faces.end());
      if (flatten(V, F, c, options.max_area_distortion)) {
        charts.push_back(std::move(c));
        break;
      }
      for (int f : c.faces) chart[f] = -1;
      budget = std::max(1, std::min(budget, static_cast<int>(c.faces.size())) / 2);
    }
  }
  return charts;
}

// Shelf packing of the chart bounding boxes, tallest first (ties by chart id), gutter apart:
// each chart's offset.
std::vector<Vector2d> pack_charts(const std::vector<Chart>& charts, double gutter) {
  const int nc = static_cast<int>(charts.size());
  std::vector<Vector2d> lo(nc), size(nc);
  double box_area = 0.0;
  for (int c = 0; c < nc; ++c) {
    lo[c] = charts[c].uv.colwise().minCoeff().transpose();
    size[c] = charts[c].uv.colwise().maxCoeff().transpose() - lo[c];
    box_area += (size[c].x() + gutter) * (size[c].y() + gutter);
  }
  std::vector<int> order(nc);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return size[a].y() > size[b].y(); });
  double width = std::sqrt(box_area);
  for (int c = 0; c < nc; ++c) width = std::max(width, size[c].x());
  std::vector<Vector2d> offset(nc);
  double x = 0.0, y = 0.0, shelf_height = 0.0;
  for (int c : order) {
    if (x > 0.0 && x + size[c].x() > width) {
      x = 0.0;
      y += shelf_height + gutter;
      shelf_height = 0.0;
    }
    offset[c] = Vector2d(x, y) - lo[c];
    x += size[c].x() + gutter;
    shelf_height = std::max(shelf_height, size[c].y());
  }
  return offset;
}

}  // namespace

TextureAtlas texture_atlas(const MatrixX3d& V, const MatrixX3i& F,
                           const TextureAtlasOptions& options) {
  validate_atlas_input(V, F, options);
  const int n = static_cast<int>(V.rows());
  const int nf = static_cast<int>(F.rows());
  const EdgeTopology topo = edge_topology(F, n);  // validates indices
  const Eigen::VectorXd areas = face_areas(V, F);
  for (int f = 0; f < nf; ++f)
    MQ_CHECK(areas(f) > 0.0 && F(f, 0) != F(f, 1) && F(f, 1) != F(f, 2) && F(f, 0) != F(f, 2),
             InvalidInput, "texture atlas: face ", f, " has zero area or a repeated vertex");
  std::vector<int> chart;
  const std::vector<Chart> charts = grow_charts(V, F, topo, options, chart);
  const std::vector<Vector2d> offset = pack_charts(charts, options.gutter * std::sqrt(areas.sum()));

  TextureAtlas atlas;
  const int nc = static_cast<int>(charts.size());
  atlas.num_charts = nc;
  atlas.face_chart = chart;
  atlas.FUV.resize(nf, 3);
  int num_uv = 0;
  for (const Chart& c : charts) num_uv += static_cast<int>(c.vertices.size());
  atlas.UV.resize(num_uv, 2);
  atlas.uv_vertex.resize(num_uv);
  int base = 0;
  for (int c = 0; c < nc; ++c) {
    const Chart& ch = charts[c];
    for (std::size_t i = 0; i < ch.vertices.size(); ++i) {
      atlas.UV.row(base + static_cast<int>(i)) =
          ch.uv.row(static_cast<int>(i)) + offset[c].transpose();
      atlas.uv_vertex[base + i] = ch.vertices[i];
    }
    for (std::size_t j = 0; j < ch.faces.size(); ++j)
      for (int k = 0; k < 3; ++k)
        atlas.FUV(ch.faces[j], k) = base + ch.local_F(static_cast<int>(j), k);
    base += static_cast<int>(ch.vertices.size());
  }
  return atlas;
}

double atlas_stretch(const MatrixX3d& V, const MatrixX3i& F, const TextureAtlas& atlas) {
  MQ_CHECK(atlas.FUV.rows() == F.rows(), InvalidInput, "atlas stretch: ", atlas.FUV.rows(),
           " UV faces for ", F.rows(), " faces");
  MQ_CHECK(F.rows() > 0, InvalidInput, "atlas stretch: no faces");
  MQ_CHECK(F.minCoeff() >= 0 && F.maxCoeff() < V.rows(), InvalidInput,
           "atlas stretch: face index out of range");
  MQ_CHECK(atlas.FUV.minCoeff() >= 0 && atlas.FUV.maxCoeff() < atlas.UV.rows(), InvalidInput,
           "atlas stretch: UV index out of range");
  double num = 0.0, a3 = 0.0, auv = 0.0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Vector3d q1 = V.row(F(f, 0)), q2 = V.row(F(f, 1)), q3 = V.row(F(f, 2));
    const Vector2d p1 = atlas.UV.row(atlas.FUV(f, 0)), p2 = atlas.UV.row(atlas.FUV(f, 1)),
                   p3 = atlas.UV.row(atlas.FUV(f, 2));
    const double A = 0.5 * tri_area2(p1, p2, p3);
    if (!(A > 0.0)) return std::numeric_limits<double>::infinity();
    // Sander et al.: partial derivatives of the map texture -> surface.
    const Vector3d Ss =
        (q1 * (p2.y() - p3.y()) + q2 * (p3.y() - p1.y()) + q3 * (p1.y() - p2.y())) / (2 * A);
    const Vector3d St =
        (q1 * (p3.x() - p2.x()) + q2 * (p1.x() - p3.x()) + q3 * (p2.x() - p1.x())) / (2 * A);
    const double area3 = 0.5 * (q2 - q1).cross(q3 - q1).norm();
    num += 0.5 * (Ss.squaredNorm() + St.squaredNorm()) * area3;
    a3 += area3;
    auv += A;
  }
  return std::sqrt(num / a3) * std::sqrt(auv / a3);
}

int count_uv_overlaps(const TextureAtlas& atlas, std::vector<std::pair<int, int>>* pairs) {
  if (pairs) pairs->clear();
  const MatrixX2d& UV = atlas.UV;
  const MatrixX3i& T = atlas.FUV;
  const int nt = static_cast<int>(T.rows());
  if (nt == 0) return 0;
  MQ_CHECK(T.minCoeff() >= 0 && T.maxCoeff() < UV.rows(), InvalidInput,
           "uv overlaps: UV index out of range");
  const Vector2d lo = UV.colwise().minCoeff().transpose();
  const Vector2d hi = UV.colwise().maxCoeff().transpose();
  const double extent = std::max((hi - lo).maxCoeff(), 1e-300);
  const double eps = 1e-12 * extent;
  const int res = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(nt))));
  const double cell = extent / res * (1 + 1e-9);
  std::vector<std::vector<int>> grid(static_cast<std::size_t>(res) * res);
  auto cell_of = [&](double v, double l) {
    return std::clamp(static_cast<int>((v - l) / cell), 0, res - 1);
  };
  std::vector<Eigen::Vector4i> range(nt);
  for (int t = 0; t < nt; ++t) {
    Vector2d a = UV.row(T(t, 0)), b = a;
    for (int k = 1; k < 3; ++k) {
      a = a.cwiseMin(UV.row(T(t, k)).transpose());
      b = b.cwiseMax(UV.row(T(t, k)).transpose());
    }
    range[t] << cell_of(a.x(), lo.x()), cell_of(a.y(), lo.y()), cell_of(b.x(), lo.x()),
        cell_of(b.y(), lo.y());
    for (int i = range[t][0]; i <= range[t][2]; ++i)
      for (int j = range[t][1]; j <= range[t][3]; ++j)
        grid[static_cast<std::size_t>(i) * res + j].push_back(t);
  }
  auto separated = [&](int s, int t) {
    for (int pass = 0; pass < 2; ++pass) {
      const int a = pass ? t : s, b = pass ? s : t;
      for (int k = 0; k < 3; ++k) {
        const Vector2d p = UV.row(T(a, k)), q = UV.row(T(a, (k + 1) % 3));
        const Vector2d nrm(q.y() - p.y(), p.x() - q.x());
        const double len = nrm.norm();
        if (!(len > 0)) continue;
        double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
        for (int m = 0; m < 3; ++m) {
          const double va = nrm.dot(UV.row(T(a, m)).transpose()) / len;
          const double vb = nrm.dot(UV.row(T(b, m)).transpose()) / len;
          amin = std::min(amin, va), amax = std::max(amax, va);
          bmin = std::min(bmin, vb), bmax = std::max(bmax, vb);
        }
        if (amax <= bmin + eps || bmax <= amin + eps) return true;
      }
    }
    return false;
  };
  int count = 0;
  std::vector<int> seen(nt, -1);
  for (int s = 0; s < nt; ++s) {
    for (int i = range[s][0]; i <= range[s][2]; ++i)
      for (int j = range[s][1]; j <= range[s][3]; ++j)
        for (int t : grid[static_cast<std::size_t>(i) * res + j]) {
          if (t <= s || seen[t] == s) continue;
          seen[t] = s;
          if (!separated(s, t)) {
            ++count;
            if (pairs) pairs->emplace_back(s, t);
          }
        }
  }
  return count;
}

}  // namespace mq
