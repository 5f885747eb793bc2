#pragma once
// Counter-based random numbers for per-pixel work: a SplitMix64 stream keyed by
// (seed, frame, pixel, purpose), so results do not depend on thread count or scheduling and no
// generator state is shared or allocated. Not for cryptography.
#include <cmath>
#include <cstdint>

#include "core/hash.h"

namespace glint::render {

// Keys that keep the streams of different uses of the same pixel independent.
enum class RandomPurpose : std::uint64_t {
  colour_noise = 1,
  depth_noise = 2,
  environment = 3,
  indirect = 4
};

class PixelRandom {
 public:
  PixelRandom(std::uint64_t seed, int frame, std::uint64_t pixel, RandomPurpose purpose)
      : state_(mix64(mix64(mix64(seed) ^ static_cast<std::uint64_t>(frame)) ^ pixel) ^
               static_cast<std::uint64_t>(purpose)) {}

  // Uniform in [0, 1).
  float uniform() { return static_cast<float>(next() >> 40) * 0x1.0p-24f; }
  // Standard normal (Box-Muller).
  float gaussian() {
    const float u1 = 1.0f - uniform();  // (0, 1]
    const float u2 = uniform();
    return std::sqrt(-2.0f * std::log(u1)) * std::cos(2.0f * float(M_PI) * u2);
  }

 private:
  std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ull;
    return mix64(state_);
  }
  std::uint64_t state_;
};

}  // namespace glint::render
