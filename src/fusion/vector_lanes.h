#pragma once
// Eight float / int32 lanes as GCC vector extensions, for the CPU kernels that project points
// into an image and read it there (TSDF integration, ICP association): one AVX2 register in
// the kernels compiled for x86-64-v3 (picked once at run time), SSE pairs in the baseline.
// Vectors are passed by reference: the calling convention of a by-value vector differs between
// the baseline and the AVX2 code.
#include <cstdint>
#include <cstring>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace glint::fusion {

inline constexpr int kLaneCount = 8;
using Floats = float __attribute__((vector_size(kLaneCount * sizeof(float))));
using Ints = std::int32_t __attribute__((vector_size(kLaneCount * sizeof(std::int32_t))));
using Bytes = std::uint8_t __attribute__((vector_size(kLaneCount)));

// Eight bytes as float lanes, and float lanes holding whole numbers in [0, 255] back into
// bytes (the TSDF's weights; exact both ways).
[[gnu::always_inline]] inline void load_bytes(const std::uint8_t* bytes, Floats& values) {
  Bytes loaded;
  std::memcpy(&loaded, bytes, sizeof(loaded));
  values = __builtin_convertvector(loaded, Floats);
}
[[gnu::always_inline]] inline void store_bytes(const Floats& values, std::uint8_t* bytes) {
  const Bytes stored = __builtin_convertvector(values, Bytes);
  std::memcpy(bytes, &stored, sizeof(stored));
}

// nearest_pixel() of every lane of `valid`: clears the lanes whose (u, v) falls outside a
// width x height image; `pixel` gets y * width + x, 0 in the lanes not valid.
[[gnu::always_inline]] inline void nearest_pixels(const Floats& u, const Floats& v, int width,
                                                  int height, Ints& valid, Ints& pixel) {
  valid &= (u >= -0.5f) & (v >= -0.5f) & (u < float(width) - 0.5f) & (v < float(height) - 0.5f);
  const Ints column = __builtin_convertvector(valid ? u + 0.5f : Floats{}, Ints);
  const Ints row = __builtin_convertvector(valid ? v + 0.5f : Floats{}, Ints);
  pixel = row * width + column;
}

// image[pixel] of each lane.
[[gnu::always_inline]] inline void gather_lane_by_lane(const float* image, const Ints& pixel,
                                                       Floats& out) {
  float values[kLaneCount];
  for (int lane = 0; lane < kLaneCount; ++lane) values[lane] = image[pixel[lane]];
  std::memcpy(&out, values, sizeof(out));
}
#if defined(__x86_64__)
// One vgatherdps instead of 8 extract-load-insert triples: integration is bound by instruction
// throughput, and they were a quarter of each row's instructions.
[[gnu::target("avx2")]] inline void gather_avx2(const float* image, const Ints& pixel,
                                                Floats& out) {
  out = Floats(_mm256_i32gather_ps(image, __m256i(pixel), sizeof(float)));
}
#endif

}  // namespace glint::fusion
