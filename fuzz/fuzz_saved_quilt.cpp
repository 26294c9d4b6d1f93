// libFuzzer target for saved quilts (issue 25): any bytes either parse into a quilt whose every
// index is in range and every value finite, or throw InvalidInput. Bytes after a valid header
// and before a valid checksum are what matters, so half the inputs get a correct checksum.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "core/common/errors.h"
#include "core/common/fnv1a.h"
#include "core/shell/saved_quilt.h"

namespace {

void check(const mq::SavedQuilt& q) {
  const int nb = q.base.num_vertices(), nf = q.base.num_faces(), nv = q.output.num_vertices();
  if (static_cast<int>(q.input_vertex.size()) != nb) __builtin_trap();
  for (const int v : q.input_vertex)
    if (v < 0 || v >= q.header.base.vertices) __builtin_trap();
  if (nf > 0 && (q.base.F.minCoeff() < 0 || q.base.F.maxCoeff() >= nb)) __builtin_trap();
  if (q.output.num_faces() > 0 && (q.output.F.minCoeff() < 0 || q.output.F.maxCoeff() >= nv))
    __builtin_trap();
  if (q.coords.size() != nv || !q.coords.bary.allFinite() || !q.coords.height.allFinite() ||
      !q.output.V.allFinite())
    __builtin_trap();
  for (const int f : q.coords.face)
    if (f < 0 || f >= nf) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size >= 20 && (data[size - 1] & 1)) {
    std::uint64_t h = mq::kFnv1aOffset;
    mq::fnv1a(h, bytes.data(), size - 8);
    std::memcpy(bytes.data() + size - 8, &h, 8);
  }
  try {
    check(mq::parse_saved_quilt(bytes, "fuzz"));
  } catch (const mq::InvalidInput&) {
  }
  return 0;
}
