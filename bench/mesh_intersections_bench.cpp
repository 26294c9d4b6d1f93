// The intersection test's throughput on chain mail, the outputs it spends its time on (the
// shell embedding's full pass and the per-ring fold tests: about a quarter of the armor job).
// A 4-in-1 sheet of 24 x 24 rings (1,152 faces each, 664k faces), bent over a cylinder so that
// the faces are not axis-aligned; one ring bent hard on its own.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "core/mesh/mesh_intersections.h"
#include "core/planar/swatch_generators.h"

namespace {

// The sheet bent round the y axis with the given radius (in ring radii): x becomes the angle.
mq::TriMesh bent_sheet(int rings) {
  mq::ChainMailOptions o;
  o.rows = rings;
  o.cols = rings;
  mq::TriMesh m = mq::chainmail_4in1(o);
  const double radius = 20;
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const double a = m.V(v, 0) / radius, r = radius + m.V(v, 2);
    m.V(v, 0) = r * std::sin(a);
    m.V(v, 2) = r * std::cos(a);
  }
  return m;
}

const mq::TriMesh& sheet() {
  static const mq::TriMesh m = bent_sheet(24);
  return m;
}

// Times find(m) on the sheet, a count of what it found reported as `found`.
template <class Find>
void time_on_sheet(benchmark::State& state, const Find& find) {
  const mq::TriMesh& m = sheet();
  size_t found = 0;
  for (auto _ : state) {
    found = find(m);
    benchmark::DoNotOptimize(found);
  }
  state.counters["faces"] = static_cast<double>(m.F.rows());
  state.counters["found"] = static_cast<double>(found);
  state.SetItemsProcessed(state.iterations() * m.F.rows());
}

void BM_AllFacePairs(benchmark::State& state) {
  mq::IntersectionOptions all;
  all.between_components_only = false;
  time_on_sheet(state, [&](const mq::TriMesh& m) {
    return mq::intersecting_face_pairs(m.V, m.F, all).size();
  });
}
BENCHMARK(BM_AllFacePairs)->Unit(benchmark::kMillisecond);

// The pairs touching the rings that moved: every third ring (about the share of the armor job's
// updates after its fold repair and ring separation), or every hundredth (a shell update).
void BM_TouchingFacePairs(benchmark::State& state) {
  const Eigen::Index faces = sheet().F.rows(), ring_faces = 2 * 48 * 12;
  std::vector<char> active(static_cast<size_t>(faces), 0);
  for (Eigen::Index f = 0; f < faces; ++f)
    active[static_cast<size_t>(f)] = (f / ring_faces) % state.range(0) == 0;
  time_on_sheet(state, [&](const mq::TriMesh& m) {
    return mq::intersecting_face_pairs_touching(m.V, m.F, active).size();
  });
}
BENCHMARK(BM_TouchingFacePairs)->Arg(3)->Arg(100)->Unit(benchmark::kMillisecond);

// One ring at a time, as the fold repair tests the elements it moved.
void BM_RingSelfIntersection(benchmark::State& state) {
  mq::ChainMailOptions o;
  o.rows = 1;
  o.cols = 1;
  mq::TriMesh ring = mq::chainmail_4in1(o);
  // Bent hard over a cylinder of one ring radius: every face tilted, none folded.
  for (Eigen::Index v = 0; v < ring.V.rows(); ++v) {
    const double a = ring.V(v, 0) / 2.0, r = 2.0 + ring.V(v, 2);
    ring.V(v, 0) = r * std::sin(a);
    ring.V(v, 2) = r * std::cos(a);
  }
  size_t folded = 0;
  for (auto _ : state) {
    folded = mq::self_intersecting_components(ring.V, ring.F).size();
    benchmark::DoNotOptimize(folded);
  }
  state.counters["faces"] = static_cast<double>(ring.F.rows());
  state.counters["found"] = static_cast<double>(folded);  // folded rings
  state.SetItemsProcessed(state.iterations() * ring.F.rows());
}
BENCHMARK(BM_RingSelfIntersection)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
