// The floor of a quilting job (issue 27): what any tool producing the same output would spend,
// measured on this machine. Reading the job's inputs (the swatch, and the base of a surface job
// or a two-triangle plane of the plane job's size), one exact closest-point query per output
// vertex against that surface (Embree BVH built included, TBB over the vertices), and writing
// the output again in its format. bench/run_jobs.py reports each job's time as a multiple of
// this, beside the paper's ratio.
//
//   job_floor --swatch SW.obj (--base BASE | --plane L W) --output OUT.obj [--runs N]
//
// Prints one JSON object: read_seconds, query_seconds, write_seconds and floor_seconds (their
// sum), each the median over the runs, and the output's vertex count. Exit 1 with one line on
// bad input.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/closest_point_query.h"
#include "core/mesh/mesh_io.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double median(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  const size_t n = x.size();
  return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

mq::TriMesh rectangle(double length, double width) {
  mq::TriMesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, length, 0, 0, length, width, 0, 0, width, 0;
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  std::string swatch_path, base_path, output_path;
  double length = 0, width = 0;
  int runs = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--swatch" && more) {
      swatch_path = argv[++i];
    } else if (a == "--base" && more) {
      base_path = argv[++i];
    } else if (a == "--output" && more) {
      output_path = argv[++i];
    } else if (a == "--runs" && more) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--plane" && i + 2 < argc) {
      length = std::atof(argv[++i]);
      width = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "job_floor: unknown or incomplete argument '%s'\n", a.c_str());
      return 2;
    }
  }
  if (swatch_path.empty() || output_path.empty() || (base_path.empty() && !(length > 0))) {
    std::fprintf(stderr,
                 "usage: job_floor --swatch SW (--base BASE | --plane L W) --output OUT "
                 "[--runs N]\n");
    return 2;
  }
  try {
    const mq::TriMesh output = mq::read_mesh(output_path);
    const std::filesystem::path out(output_path);
    const std::string copy =
        (out.parent_path() / ("floor_copy" + out.extension().string())).string();
    std::vector<double> read_s, query_s, write_s;
    for (int r = 0; r < runs; ++r) {
      auto t0 = Clock::now();
      const mq::TriMesh swatch = mq::read_mesh(swatch_path);
      const mq::TriMesh base =
          base_path.empty() ? rectangle(length, width) : mq::read_mesh(base_path);
      read_s.push_back(seconds_since(t0));
      t0 = Clock::now();
      const mq::ClosestPointQuery query(base.V, base.F);
      std::vector<int> face(static_cast<size_t>(output.V.rows()));
      tbb::parallel_for(Eigen::Index(0), output.V.rows(), [&](Eigen::Index v) {
        face[static_cast<size_t>(v)] = query.closest(mq::Vector3d(output.V.row(v))).face;
      });
      query_s.push_back(seconds_since(t0));
      if (swatch.F.rows() == 0 || std::count(face.begin(), face.end(), -1) > 0) {
        std::fprintf(stderr, "job_floor: a query found no face\n");
        return 1;
      }
      t0 = Clock::now();
      mq::write_mesh(copy, output);
      write_s.push_back(seconds_since(t0));
    }
    std::filesystem::remove(copy);
    std::filesystem::remove(std::filesystem::path(copy).replace_extension(".mtl"));
    const double read = median(read_s), q = median(query_s), write = median(write_s);
    std::printf(
        "{\"read_seconds\": %.6f, \"query_seconds\": %.6f, \"write_seconds\": %.6f, "
        "\"floor_seconds\": %.6f, \"output_vertices\": %lld, \"runs\": %d}\n",
        read, q, write, read + q + write, static_cast<long long>(output.V.rows()), runs);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "job_floor: %s\n", e.what());
    return 1;
  }
  return 0;
}
