#pragma once
// exp(x) for x in [-2e6, 0] without a library call, so that loops calling it vectorise (GCC does
// not vectorise std::exp without -ffast-math): x = n ln 2 + r with |r| <= ln 2 / 2 (ln 2 split
// in two for an exact product), exp(r) by its degree-7 Taylor polynomial (relative error below
// 2e-7 there), 2^n by building the exponent; 0 below x = -87.3, where 2^n leaves the normal
// floats. (A caller that clamps x at a constant may find GCC splitting its loop at the clamp
// instead of vectorising it: the flush to 0 makes a clamp at -87 unnecessary.)
#include <algorithm>
#include <bit>
#include <cstdint>

namespace glint {

inline float exp_nonpositive(float x) {
  constexpr float kLog2e = 1.44269504f, kLn2High = 0.693145752f, kLn2Low = 1.42860677e-6f;
  constexpr float kRound = 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer
  const float rounded = x * kLog2e + kRound;
  const float n = rounded - kRound;
  const float r = (x - n * kLn2High) - n * kLn2Low;
  float p = 1.0f / 5040;
  p = p * r + 1.0f / 720;
  p = p * r + 1.0f / 120;
  p = p * r + 1.0f / 24;
  p = p * r + 1.0f / 6;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  // n as an integer: `rounded` keeps kRound's exponent (|n| < 2^22), so its mantissa counts n.
  const std::int32_t integer =
      std::bit_cast<std::int32_t>(rounded) - std::bit_cast<std::int32_t>(kRound);
  const float scale = std::bit_cast<float>(std::max(integer + 127, 0) << 23);
  return p * scale;
}

}  // namespace glint
