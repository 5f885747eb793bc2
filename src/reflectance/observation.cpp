#include "reflectance/observation.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "core/cpu_level.h"

namespace glint::reflectance {

std::uint16_t half_from_float(float value) {
  if (!(value > 0.0f)) return 0;
  constexpr float kLargest = 65504.0f, kSmallestNormal = 6.103515625e-05f;  // 2^-14
  if (value >= kLargest) return 0x7bff;
  // Below 2^-14 a half is subnormal: a count of 2^-24 steps (exact in float arithmetic).
  if (value < kSmallestNormal) return std::uint16_t(std::lrint(value * 16777216.0f));
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
  const std::uint32_t exponent = (bits >> 23) - 127 + 15, mantissa = bits & 0x7fffff;
  // Rounding up may carry into the exponent, which is the right neighbour.
  return std::uint16_t(((exponent << 10) | (mantissa >> 13)) + ((mantissa >> 12) & 1));
}

Observation::Observation(const Eigen::Vector3f& colour, const Eigen::Vector3f& direction,
                         std::uint32_t frame)
    : frame_(frame) {
  for (int c = 0; c < 3; ++c) {
    colour_[c] = half_from_float(colour[c]);
    direction_[c] = std::int16_t(std::lrint(std::clamp(direction[c], -1.0f, 1.0f) * kUnit));
  }
}

// What the vectorised similarity() below relies on: the direction is 16-bit words 3-5.
struct ObservationLanes {
  static constexpr float kScale = 1.0f / (float(Observation::kUnit) * float(Observation::kUnit));
  static_assert(offsetof(Observation, direction_) == 6);
};

namespace {

// An observation's most similar other one (an entry of NearestObservations).
struct Nearest {
  float similarity = -2.0f;
  std::uint8_t slot = 0;
};

// A full voxel's insertion is 60-90 direction dot products and a few searches for the most
// similar one, whose winner is as good as random to the branch predictor; they run scalar
// (Scalar), 8 at a time with AVX2 (Avx2) or 16 at a time with AVX-512 (Avx512). All give the
// same results bit for bit.
struct Scalar {
  // out[j] = to.similarity(slots[j]) for j < count (Avx2 writes on to the next multiple of 8).
  static void similarities(const Observation* slots, int count, const Observation& to, float* out) {
    for (int j = 0; j < count; ++j) out[j] = to.similarity(slots[j]);
  }
  // The first largest of values[0, count) above -2, and its index; {-2, 0} when there is none.
  static Nearest first_largest(const float* values, int count) {
    Nearest best;
    for (int j = 0; j < count; ++j)
      if (values[j] > best.similarity) best = {values[j], std::uint8_t(j)};
    return best;
  }
};

#if defined(__x86_64__)
struct Avx512 {
  // Four observations per register. As 16-bit words an observation is colour 0-2, direction 3-5
  // and frame 6-7; vpmaddwd multiplies the words with `to`'s direction (zeros elsewhere) and adds
  // them pairwise, leaving d0 t0 in its 32-bit lane 1 and d1 t1 + d2 t2 in lane 2. Their sum is
  // similarity()'s integer dot product exactly (no partial sum of two unit vectors' products
  // overflows), then converted and scaled as there.
  [[gnu::target("arch=x86-64-v4")]] static void similarities(const Observation* slots, int count,
                                                             const Observation& to, float* out) {
    std::int16_t words[8];
    std::memcpy(words, &to, sizeof(to));
    const __m512i weights = _mm512_maskz_broadcast_i32x4(
        0xffff, _mm_setr_epi16(0, 0, 0, words[3], words[4], words[5], 0, 0));
    const __m512 scale = _mm512_set1_ps(ObservationLanes::kScale);
    // Lane 1 of each observation of two registers.
    const __m512i lane_one = _mm512_setr_epi32(1, 5, 9, 13, 17, 21, 25, 29, 0, 0, 0, 0, 0, 0, 0, 0);
    const auto* lanes = reinterpret_cast<const std::int32_t*>(slots);
    for (int first = 0; first < count; first += 16) {
      __m512i dots[4];
      for (int r = 0; r < 4; ++r) {
        const int held = std::clamp(count - first - 4 * r, 0, 4);
        const __m512i loaded = _mm512_maskz_loadu_epi32(__mmask16((1u << (4 * held)) - 1),
                                                        lanes + 4 * (first + 4 * r));
        const __m512i pairs = _mm512_madd_epi16(loaded, weights);
        dots[r] = _mm512_add_epi32(pairs, _mm512_bsrli_epi128(pairs, 4));
      }
      const __m512i low = _mm512_permutex2var_epi32(dots[0], lane_one, dots[1]);
      const __m512i high = _mm512_permutex2var_epi32(dots[2], lane_one, dots[3]);
      const __m512i all = _mm512_maskz_shuffle_i64x2(0xff, low, high, _MM_SHUFFLE(1, 0, 1, 0));
      _mm512_mask_storeu_ps(out + first, __mmask16((1u << std::min(16, count - first)) - 1),
                            _mm512_mul_ps(_mm512_maskz_cvtepi32_ps(0xffff, all), scale));
    }
  }

  // The largest value first, then the first lane that holds it.
  [[gnu::target("arch=x86-64-v4")]] static Nearest first_largest(const float* values, int count) {
    const __m512 floor = _mm512_set1_ps(-2.0f);
    __m512 largest = floor;
    for (int first = 0; first < count; first += 16)
      largest = _mm512_maskz_max_ps(
          0xffff, largest, _mm512_mask_loadu_ps(floor, valid(count - first), values + first));
    // Halving by lane rotations (GCC 12 warns about the undefined operands of
    // _mm512_reduce_max_ps and of the unmasked intrinsics).
    for (int half = 8; half >= 1; half /= 2) {
      const __m512i rotate =
          _mm512_add_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                           _mm512_set1_epi32(half));
      largest = _mm512_maskz_max_ps(0xffff, largest,
                                    _mm512_maskz_permutexvar_ps(0xffff, rotate, largest));
    }
    const float best = _mm512_cvtss_f32(largest);
    if (!(best > -2.0f)) return {};
    for (int first = 0;; first += 16) {
      const __mmask16 equal = _mm512_mask_cmp_ps_mask(
          valid(count - first), _mm512_maskz_loadu_ps(valid(count - first), values + first),
          _mm512_set1_ps(best), _CMP_EQ_OQ);
      if (equal) {
        const int index = first + std::countr_zero(unsigned(equal));
        return {values[index], std::uint8_t(index)};
      }
    }
  }

  [[gnu::target("arch=x86-64-v4")]] static __mmask16 valid(int left) {
    return __mmask16(left >= 16 ? 0xffff : (1u << left) - 1);
  }
};

// The same searches 8 at a time where the CPU has AVX2 (x86-64-v3) but not AVX-512 (Zen 3, and
// Intel's client cores): two observations per register, their vpmaddwd pairs summed by
// horizontal adds into similarity()'s integer dot products, then converted and scaled as there.
struct Avx2 {
  [[gnu::target("arch=x86-64-v3")]] static void similarities(const Observation* slots, int count,
                                                             const Observation& to, float* out) {
    std::int16_t words[8];
    std::memcpy(words, &to, sizeof(to));
    const __m256i weights = _mm256_setr_epi16(0, 0, 0, words[3], words[4], words[5], 0, 0, 0, 0, 0,
                                              words[3], words[4], words[5], 0, 0);
    const __m256 scale = _mm256_set1_ps(ObservationLanes::kScale);
    // After the two rounds of horizontal adds the lanes hold observations 0 2 4 6 1 3 5 7.
    const __m256i in_order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
    const auto* lanes = reinterpret_cast<const std::int32_t*>(slots);
    for (int first = 0; first < count; first += 8) {
      __m256i pairs[4];
      for (int r = 0; r < 4; ++r) {
        const int held = std::clamp(count - first - 2 * r, 0, 2);  // observations in register r
        pairs[r] = _mm256_madd_epi16(
            _mm256_maskload_epi32(lanes + 4 * (first + 2 * r), valid(4 * held)), weights);
      }
      const __m256i dots = _mm256_hadd_epi32(_mm256_hadd_epi32(pairs[0], pairs[1]),
                                             _mm256_hadd_epi32(pairs[2], pairs[3]));
      _mm256_storeu_ps(
          out + first,
          _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_permutevar8x32_epi32(dots, in_order)), scale));
    }
  }

  // The largest value first, then the first lane that holds it.
  [[gnu::target("arch=x86-64-v3")]] static Nearest first_largest(const float* values, int count) {
    __m256 largest = _mm256_set1_ps(-2.0f);
    for (int first = 0; first < count; first += 8)
      largest = _mm256_max_ps(largest, load(values + first, count - first));
    largest = _mm256_max_ps(largest, _mm256_permute2f128_ps(largest, largest, 1));
    largest = _mm256_max_ps(largest, _mm256_shuffle_ps(largest, largest, _MM_SHUFFLE(1, 0, 3, 2)));
    largest = _mm256_max_ps(largest, _mm256_shuffle_ps(largest, largest, _MM_SHUFFLE(2, 3, 0, 1)));
    const float best = _mm256_cvtss_f32(largest);
    if (!(best > -2.0f)) return {};
    for (int first = 0;; first += 8) {
      const int equal = _mm256_movemask_ps(
          _mm256_cmp_ps(load(values + first, count - first), _mm256_set1_ps(best), _CMP_EQ_OQ));
      if (equal) {
        const int index = first + std::countr_zero(unsigned(equal));
        return {values[index], std::uint8_t(index)};
      }
    }
  }

  // All-ones in the 32-bit lanes below `left`.
  [[gnu::target("arch=x86-64-v3")]] static __m256i valid(int left) {
    return _mm256_cmpgt_epi32(_mm256_set1_epi32(left), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  }
  // values[0, min(8, left)), -2 (below every similarity) in the lanes beyond.
  [[gnu::target("arch=x86-64-v3")]] static __m256 load(const float* values, int left) {
    const __m256i mask = valid(left);
    return _mm256_blendv_ps(_mm256_set1_ps(-2.0f), _mm256_maskload_ps(values, mask),
                            _mm256_castsi256_ps(mask));
  }
};
#endif

// The similarity buffers are whole vectors long: Avx2 stores 8 lanes where the count ends
// (AMD's masked stores are microcoded, slower than the dot products they store).
constexpr int kSimilarityCapacity = (kMaxObservationsPerVoxel + 15) / 16 * 16;

// The nearest other observation of slot i among slots[0, count).
template <class Simd>
[[gnu::always_inline]] inline Nearest nearest_of(const Observation* slots, int count, int i) {
  float similarity[kSimilarityCapacity];
  Simd::similarities(slots, count, slots[i], similarity);
  similarity[i] = -2.0f;  // not its own nearest
  return Simd::first_largest(similarity, count);
}

// Stores `added` in slot r (a new slot when r == count) and updates every nearest entry;
// `similarity[j]` = added . slots[j] for the other slots (similarity[r] is overwritten).
template <class Simd>
[[gnu::always_inline]] inline void place(Observation* slots, NearestObservations nearest, int count,
                                         int r, const Observation& added, float* similarity) {
  slots[r] = added;
  similarity[r] = -2.0f;
  const Nearest own = Simd::first_largest(similarity, count);
  nearest.similarity[r] = own.similarity;
  nearest.slot[r] = own.slot;
  for (int i = 0; i < count; ++i) {
    if (i == r) continue;
    Nearest updated;
    if (nearest.slot[i] == r && nearest.similarity[i] > -2.0f)
      updated = nearest_of<Simd>(slots, count, i);  // its nearest was replaced
    else if (similarity[i] > nearest.similarity[i])
      updated = {similarity[i], std::uint8_t(r)};
    else
      continue;
    nearest.similarity[i] = updated.similarity;
    nearest.slot[i] = updated.slot;
  }
}

template <class Simd>
[[gnu::always_inline]] inline int insert(Observation* slots, NearestObservations nearest, int count,
                                         int capacity, const Observation& added) {
  float similarity[kSimilarityCapacity];
  Simd::similarities(slots, count, added, similarity);
  if (count < capacity) {
    place<Simd>(slots, nearest, count + 1, count, added, similarity);
    return count + 1;
  }
  // The most similar stored pair, and the stored observation most similar to the new one.
  const Nearest pair = Simd::first_largest(nearest.similarity, capacity);
  const int first = pair.slot, closest_to_new = Simd::first_largest(similarity, capacity).slot;
  int dropped;
  if (similarity[closest_to_new] > pair.similarity) {
    // The pair (new, closest_to_new): the older goes, the stored one unless it is newer.
    if (added.frame() < slots[closest_to_new].frame()) return capacity;
    dropped = closest_to_new;
  } else {
    const int second = nearest.slot[first];
    dropped = slots[first].frame() <= slots[second].frame() ? first : second;
  }
  place<Simd>(slots, nearest, capacity, dropped, added, similarity);
  return capacity;
}

using InsertKernel = int (*)(Observation*, NearestObservations, int, int, const Observation&);

[[gnu::flatten]] int insert_baseline(Observation* slots, NearestObservations nearest, int count,
                                     int capacity, const Observation& added) {
  return insert<Scalar>(slots, nearest, count, capacity, added);
}

#if defined(__x86_64__)
[[gnu::target("arch=x86-64-v3"), gnu::flatten]] int insert_x86_64_v3(Observation* slots,
                                                                     NearestObservations nearest,
                                                                     int count, int capacity,
                                                                     const Observation& added) {
  return insert<Avx2>(slots, nearest, count, capacity, added);
}

[[gnu::target("arch=x86-64-v4"), gnu::flatten]] int insert_x86_64_v4(Observation* slots,
                                                                     NearestObservations nearest,
                                                                     int count, int capacity,
                                                                     const Observation& added) {
  return insert<Avx512>(slots, nearest, count, capacity, added);
}
#endif

InsertKernel kernel_of(InsertionKernel kernel) {
  switch (kernel) {
#if defined(__x86_64__)
    case InsertionKernel::kAvx512:
      return insert_x86_64_v4;
    case InsertionKernel::kAvx2:
      return insert_x86_64_v3;
#endif
    default:
      return insert_baseline;
  }
}

}  // namespace

std::vector<InsertionKernel> supported_insertion_kernels() {
  std::vector<InsertionKernel> kernels{InsertionKernel::kScalar};
#if defined(__x86_64__)
  if (cpu_has_x86_64_v3()) kernels.push_back(InsertionKernel::kAvx2);
  if (cpu_has_x86_64_v4()) kernels.push_back(InsertionKernel::kAvx512);
#endif
  return kernels;
}

int insert_observation(InsertionKernel kernel, Observation* slots, NearestObservations nearest,
                       int count, int capacity, const Observation& added) {
  if (capacity <= 0) return 0;
  return kernel_of(kernel)(slots, nearest, count, capacity, added);
}

int insert_observation(Observation* slots, NearestObservations nearest, int count, int capacity,
                       const Observation& added) {
  if (capacity <= 0) return 0;
  static const InsertKernel kernel = kernel_of(supported_insertion_kernels().back());
  return kernel(slots, nearest, count, capacity, added);
}

}  // namespace glint::reflectance
