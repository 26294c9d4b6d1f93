// FNV-1a, 64 bits: a fast, deterministic hash of raw bytes for in-memory cache keys (not for
// anything persistent or adversarial).
#pragma once

#include <cstddef>
#include <cstdint>

namespace mq {

constexpr std::uint64_t kFnv1aOffset = 14695981039346656037ull;

// Mixes `bytes` bytes at `data` into h (start from kFnv1aOffset).
inline void fnv1a(std::uint64_t& h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
}

}  // namespace mq
