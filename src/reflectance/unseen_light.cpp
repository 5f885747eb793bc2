#include "reflectance/unseen_light.h"

#include <algorithm>
#include <cassert>

namespace glint::reflectance {
namespace {

// Median of value(order[first..last)) (reorders that range of `order`).
template <class Value>
float median_over(std::vector<int>::iterator first, std::vector<int>::iterator last, Value value) {
  const auto n = last - first;
  const auto middle = first + n / 2;
  const auto less = [&](int a, int b) { return value(a) < value(b); };
  std::nth_element(first, middle, last, less);
  if (n % 2 == 1) return value(*middle);
  return 0.5f * (value(*middle) + value(*std::max_element(first, middle, less)));
}

}  // namespace

std::optional<RadianceLine> fit_radiance_line(std::span<const Eigen::Vector3f> irradiance,
                                              std::span<const Eigen::Vector3f> radiance,
                                              const UnseenLightFitParams& params,
                                              std::vector<int>& order) {
  assert(irradiance.size() == radiance.size());
  const int n = int(irradiance.size());
  if (n < std::max(3, params.min_voxels)) return std::nullopt;
  order.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) order[std::size_t(i)] = i;
  // The voxels sorted into thirds by their irradiance's luminance.
  const auto luminance = [&](int i) { return irradiance[std::size_t(i)].mean(); };
  const auto third = order.begin() + n / 3, two_thirds = order.end() - n / 3;
  std::nth_element(order.begin(), third, order.end(),
                   [&](int a, int b) { return luminance(a) < luminance(b); });
  std::nth_element(third, two_thirds, order.end(),
                   [&](int a, int b) { return luminance(a) < luminance(b); });
  const float low_luminance = median_over(order.begin(), third, luminance);
  const float high_luminance = median_over(two_thirds, order.end(), luminance);
  if (!(high_luminance > 0 && high_luminance >= params.min_leverage * low_luminance))
    return std::nullopt;

  // Slopes first: the intercepts' medians reorder the whole range, thirds included.
  RadianceLine line{.typical_irradiance = high_luminance};
  for (int c = 0; c < 3; ++c) {
    const auto e = [&](int i) { return irradiance[std::size_t(i)][c]; };
    const auto d = [&](int i) { return radiance[std::size_t(i)][c]; };
    const float run =
        median_over(two_thirds, order.end(), e) - median_over(order.begin(), third, e);
    const float rise =
        median_over(two_thirds, order.end(), d) - median_over(order.begin(), third, d);
    if (!(run > 0 && rise > 0)) return std::nullopt;
    line.slope[c] = rise / run;  // kd / pi
  }
  for (int c = 0; c < 3; ++c)
    line.intercept[c] = median_over(order.begin(), order.end(), [&](int i) {
      return radiance[std::size_t(i)][c] - line.slope[c] * irradiance[std::size_t(i)][c];
    });
  return line;
}

}  // namespace glint::reflectance
