// libFuzzer target for the mesh readers (issue 14). Built three times, with MESHQUILT_FUZZ_FORMAT
// 0 (OBJ), 1 (PLY) or 2 (OFF): `cmake -DMESHQUILT_FUZZ=ON` with clang (see fuzz/README.md).
// Any exception other than InvalidInput, a crash, a sanitizer report, a leak, a timeout or an
// allocation over the limit is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/common/errors.h"
#include "core/mesh/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr mq::MeshFormat kFormats[] = {mq::MeshFormat::Obj, mq::MeshFormat::Ply,
                                         mq::MeshFormat::Off};
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const mq::TriMesh m = mq::read_mesh_data(bytes, kFormats[MESHQUILT_FUZZ_FORMAT], "fuzz");
    // What a reader returns, the rest of the tool relies on: indices in range, finite values.
    if (m.F.rows() == 0) __builtin_trap();
    if (m.F.minCoeff() < 0 || m.F.maxCoeff() >= m.V.rows()) __builtin_trap();
    if (!m.V.allFinite()) __builtin_trap();
    if (m.N.rows() != 0 && (m.N.rows() != m.V.rows() || !m.N.allFinite())) __builtin_trap();
  } catch (const mq::InvalidInput&) {
  }
  return 0;
}
