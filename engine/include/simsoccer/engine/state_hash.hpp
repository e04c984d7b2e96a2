// 64-bit hash of a world state's canonical byte image (FNV-1a over the
// values' bytes): equal hashes mean bit-identical states on one build.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>

namespace simsoccer::engine {

inline uint64_t hashBytes(const void* data, size_t size, uint64_t seed = 0xcbf29ce484222325ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  uint64_t h = seed;
  for (size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

inline uint64_t hashValues(std::span<const double> values, uint64_t seed = 0xcbf29ce484222325ull) {
  return hashBytes(values.data(), values.size_bytes(), seed);
}

}  // namespace simsoccer::engine
