// libFuzzer target for the per-vertex files (issues 14 and 25): MESHQUILT_FUZZ_FORMAT 0 reads
// the bytes as a --keys file, 1 as a --field-file, 2 as a --mask, 3 as a --size-map, each for a
// base of 64 vertices (8 x 8, 98 faces). The readers take a path, so the bytes go to one file
// in $TMPDIR (or /tmp) first.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/common/errors.h"
#include "core/surface/tangent_field.h"
#include "core/surface/vertex_map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = [] {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir ? dir : "/tmp") + "/meshquilt-fuzz-" + std::to_string(::getpid()) +
           ".txt";
  }();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  constexpr int kVertices = 64;
  static const mq::TriMesh base = [] {
    mq::TriMesh m;
    m.V.resize(kVertices, 3);
    m.F.resize(2 * 7 * 7, 3);
    for (int i = 0; i < kVertices; ++i) m.V.row(i) << i % 8, i / 8, 0;
    int f = 0;
    for (int y = 0; y < 7; ++y)
      for (int x = 0; x < 7; ++x) {
        const int a = 8 * y + x;
        m.F.row(f++) << a, a + 1, a + 9;
        m.F.row(f++) << a, a + 9, a + 8;
      }
    return m;
  }();
  try {
    if (MESHQUILT_FUZZ_FORMAT == 0) {
      for (const mq::KeyVector& k : mq::read_key_vectors(path, kVertices))
        if (k.vertex < 0 || k.vertex >= kVertices || !k.direction.allFinite()) __builtin_trap();
    } else if (MESHQUILT_FUZZ_FORMAT == 1) {
      const mq::MatrixX3d v = mq::read_vertex_vector_field(path, kVertices);
      if (v.rows() != kVertices || !v.allFinite()) __builtin_trap();
    } else if (MESHQUILT_FUZZ_FORMAT == 2) {
      const mq::SurfaceMask m = mq::read_surface_mask(path, base);
      if (m.face.empty() == (m.vertex_weight.size() == 0)) __builtin_trap();
      if (m.vertex_weight.size() &&
          (m.vertex_weight.size() != kVertices || !(m.vertex_weight.minCoeff() >= 0) ||
           !(m.vertex_weight.maxCoeff() <= 1)))
        __builtin_trap();
    } else {
      const Eigen::VectorXd s = mq::read_size_map(path, base);
      if (s.size() != kVertices || !s.allFinite() || !(s.minCoeff() > 0)) __builtin_trap();
    }
  } catch (const mq::InvalidInput&) {
  }
  return 0;
}
