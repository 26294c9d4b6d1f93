// Read and write throughput of the mesh file formats on a 1M-face regular grid.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/mesh/mesh_io.h"
#include "core/planar/swatch_generators.h"

namespace {

// Open grid in the z = 0 plane with nx by ny quads split in two, slightly perturbed so that
// coordinates use all significant digits as scanned meshes do.
mq::TriMesh grid(int nx, int ny) {
  mq::TriMesh g;
  g.V.resize((nx + 1) * (ny + 1), 3);
  g.F.resize(2 * nx * ny, 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      g.V.row(j * (nx + 1) + i) << i / 3.0, j / 7.0, 0.001 * ((i * 7919 + j * 104729) % 1000) / 3.0;
  int f = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
      g.F.row(f++) << a, b, c;
      g.F.row(f++) << a, c, d;
    }
  return g;
}

const char* kNames[] = {"bench.obj", "bench.off", "bench.ply", "bench_ascii.ply"};

std::string bench_path(int format) {
  return (std::filesystem::temp_directory_path() /
          ("meshquilt_bench_" + std::to_string(::getpid()) + "_" + kNames[format]))
      .string();
}

mq::WriteOptions options_for(int format) {
  mq::WriteOptions o;
  o.binary = format != 3;
  return o;
}

// An output as `surface` writes it: a chain mail sheet of 24 x 24 rings (664k faces) as OBJ with
// element groups, materials and corner normals.
void BM_WriteQuilt(benchmark::State& state) {
  mq::ChainMailOptions c;
  c.rows = 24;
  c.cols = 24;
  const mq::TriMesh mesh = mq::chainmail_4in1(c);
  const std::string path = bench_path(0);
  mq::WriteOptions o;
  o.write_normals = true;
  o.write_elements = true;
  for (auto _ : state) mq::write_mesh(path, mesh, o);
  state.counters["faces"] = mesh.num_faces();
  state.counters["MB"] = std::filesystem::file_size(path) / 1e6;
  std::filesystem::remove(path);
  std::filesystem::remove(std::filesystem::path(path).replace_extension(".mtl"));
}
BENCHMARK(BM_WriteQuilt)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteMesh(benchmark::State& state) {
  const int format = static_cast<int>(state.range(0));
  const mq::TriMesh mesh = grid(708, 708);
  const std::string path = bench_path(format);
  for (auto _ : state) mq::write_mesh(path, mesh, options_for(format));
  state.counters["faces"] = mesh.num_faces();
  state.counters["MB"] = std::filesystem::file_size(path) / 1e6;
  state.SetLabel(kNames[format]);
  std::filesystem::remove(path);
}

void BM_ReadMesh(benchmark::State& state) {
  const int format = static_cast<int>(state.range(0));
  const mq::TriMesh mesh = grid(708, 708);
  const std::string path = bench_path(format);
  mq::write_mesh(path, mesh, options_for(format));
  int faces = 0;
  for (auto _ : state) {
    const mq::TriMesh m = mq::read_mesh(path);
    faces = m.num_faces();
    benchmark::DoNotOptimize(m.V.data());
  }
  state.counters["faces"] = faces;
  state.SetLabel(kNames[format]);
  std::filesystem::remove(path);
}

BENCHMARK(BM_WriteMesh)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadMesh)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
