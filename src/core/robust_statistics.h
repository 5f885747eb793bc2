#pragma once
// Medians and spreads of samples that may hold outliers (voxels in shadows the geometry misses,
// textures): partial sorts in place, no allocation.
#include <algorithm>
#include <cmath>
#include <span>

namespace glint {

// The upper median of non-empty `values` (reordered).
inline float median_in_place(std::span<float> values) {
  const auto middle = values.begin() + std::ptrdiff_t(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// 1.4826 times the median absolute deviation of non-empty `values` from their `median`: a normal
// distribution's standard deviation, robust to a minority of outliers. `values` become the
// absolute deviations.
inline float robust_spread_in_place(std::span<float> values, float median) {
  for (float& value : values) value = std::fabs(value - median);
  return 1.4826f * median_in_place(values);
}

}  // namespace glint
