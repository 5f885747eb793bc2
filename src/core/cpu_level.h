#pragma once
// Run-time checks for the x86-64 psABI micro-architecture levels that glint's hand-vectorised
// kernels are compiled for ([[gnu::target("arch=x86-64-v3")]] and -v4).
// GCC answers __builtin_cpu_supports("x86-64-v3") itself; clang before 16 (the fuzz build's
// clang-14) knows only single features, so there a level is its defining vector features.
#if defined(__x86_64__)

namespace glint {

// AVX2 + FMA + BMI2 (x86-64-v3).
inline bool cpu_has_x86_64_v3() {
#if defined(__clang__) && __clang_major__ < 16
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
         __builtin_cpu_supports("bmi2");
#else
  return __builtin_cpu_supports("x86-64-v3");
#endif
}

// x86-64-v3 + AVX-512 F, BW, CD, DQ and VL (x86-64-v4).
inline bool cpu_has_x86_64_v4() {
#if defined(__clang__) && __clang_major__ < 16
  return cpu_has_x86_64_v3() && __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512cd") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
  return __builtin_cpu_supports("x86-64-v4");
#endif
}

}  // namespace glint

#endif
