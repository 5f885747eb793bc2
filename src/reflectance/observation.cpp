#include "reflectance/observation.h"

#include <algorithm>
#include <bit>
#include <cmath>

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

namespace {

// The nearest other observation of slot i among slots[0, count).
NearestObservation nearest_of(const Observation* slots, int count, int i) {
  NearestObservation best;
  for (int j = 0; j < count; ++j) {
    if (j == i) continue;
    const float similarity = slots[i].similarity(slots[j]);
    if (similarity > best.similarity) best = {similarity, std::uint8_t(j)};
  }
  return best;
}

// Stores `added` in slot r (a new slot when r == count) and updates every nearest entry;
// `similarity[j]` = added . slots[j] for the other slots.
void place(Observation* slots, NearestObservation* nearest, int count, int r,
           const Observation& added, const float* similarity) {
  slots[r] = added;
  nearest[r] = {};
  for (int j = 0; j < count; ++j) {
    if (j == r) continue;
    if (similarity[j] > nearest[r].similarity) nearest[r] = {similarity[j], std::uint8_t(j)};
  }
  for (int i = 0; i < count; ++i) {
    if (i == r) continue;
    if (nearest[i].slot == r && nearest[i].similarity > -2.0f)
      nearest[i] = nearest_of(slots, count, i);  // its nearest was replaced
    else if (similarity[i] > nearest[i].similarity)
      nearest[i] = {similarity[i], std::uint8_t(r)};
  }
}

}  // namespace

int insert_observation(Observation* slots, NearestObservation* nearest, int count, int capacity,
                       const Observation& added) {
  if (capacity <= 0) return 0;
  float similarity[256];
  for (int j = 0; j < count; ++j) similarity[j] = added.similarity(slots[j]);
  if (count < capacity) {
    place(slots, nearest, count + 1, count, added, similarity);
    return count + 1;
  }
  // The most similar stored pair, and the stored observation most similar to the new one.
  int first = 0;
  for (int i = 1; i < capacity; ++i)
    if (nearest[i].similarity > nearest[first].similarity) first = i;
  int closest_to_new = 0;
  for (int j = 1; j < capacity; ++j)
    if (similarity[j] > similarity[closest_to_new]) closest_to_new = j;
  int dropped;
  if (similarity[closest_to_new] > nearest[first].similarity) {
    // The pair (new, closest_to_new): the older goes, the stored one unless it is newer.
    if (added.frame() < slots[closest_to_new].frame()) return capacity;
    dropped = closest_to_new;
  } else {
    const int second = nearest[first].slot;
    dropped = slots[first].frame() <= slots[second].frame() ? first : second;
  }
  place(slots, nearest, capacity, dropped, added, similarity);
  return capacity;
}

}  // namespace glint::reflectance
