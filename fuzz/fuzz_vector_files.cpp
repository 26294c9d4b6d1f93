// libFuzzer target for the guidance files (issue 14): MESHQUILT_FUZZ_FORMAT 0 reads the bytes
// as a --keys file, 1 as a --field-file, each for a base of 64 vertices. The readers take a
// path, so the bytes go to one file in $TMPDIR (or /tmp) first.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/common/errors.h"
#include "core/surface/tangent_field.h"

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
  try {
    if (MESHQUILT_FUZZ_FORMAT == 0) {
      for (const mq::KeyVector& k : mq::read_key_vectors(path, kVertices))
        if (k.vertex < 0 || k.vertex >= kVertices || !k.direction.allFinite()) __builtin_trap();
    } else {
      const mq::MatrixX3d v = mq::read_vertex_vector_field(path, kVertices);
      if (v.rows() != kVertices || !v.allFinite()) __builtin_trap();
    }
  } catch (const mq::InvalidInput&) {
  }
  return 0;
}
