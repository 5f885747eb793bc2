#pragma once
// SplitMix64's finaliser: a well-mixed 64-bit hash of a counter or a key, for streams and samples
// that must not depend on thread count or scheduling. Not for cryptography.
#include <cstdint>

namespace glint {

inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace glint
