#include "reflectance/albedo_refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <span>
#include <utility>
#if defined(__SSE__)
#include <immintrin.h>
#endif

#include "core/error.h"
#include "core/robust_statistics.h"
#include "reflectance/light_incidence.h"
#include "render/ward.h"

namespace glint::reflectance {
namespace {

// One observation's eq. (7) albedo: red, green, blue and an unused lane.
using Channels = float __attribute__((vector_size(4 * sizeof(float))));

// Batcher's odd-even merge sort of kNetworkSize elements as its compare-exchange pairs:
// (p^2 - p + 4) 2^(p - 2) - 1 = 191 of them for 2^p = 32.
constexpr int kNetworkSize = 32;
constexpr std::size_t kNetworkPairs = 191;
// A compare-exchange that keeps the minimum on wire `low` and the maximum on wire `high`, or
// only the one of them that a later step reads.
struct CompareExchange {
  std::uint8_t low = 0, high = 0;
  bool keeps_low = true, keeps_high = true;
};
struct Network {
  std::array<CompareExchange, kNetworkPairs> pairs{};
  std::size_t count = 0;
};
constexpr Network merge_sort_network() {
  Network network;
  for (int p = 1; p < kNetworkSize; p *= 2)
    for (int k = p; k >= 1; k /= 2)
      for (int j = k % p; j + k < kNetworkSize; j += 2 * k)
        for (int i = 0; i < k && i + j + k < kNetworkSize; ++i)
          if ((i + j) / (2 * p) == (i + j + k) / (2 * p))
            network.pairs.at(network.count++) = {std::uint8_t(i + j), std::uint8_t(i + j + k)};
  return network;
}

// The sorting network pruned to the two middle outputs (wires 15 and 16): walking it backwards
// from them, a step stays when it writes a wire that a later kept step (or the output) reads,
// and keeps only the outputs read. The median of the 32 values is the median of a voxel's n
// observations when the 32 - n padding values are split evenly between -inf and +inf (the odd
// one +inf): 157 of the 191 steps remain, with 284 of their 382 min / max.
constexpr int kMiddle = kNetworkSize / 2;
constexpr Network middle_network() {
  const Network sort = merge_sort_network();
  std::array<bool, kNetworkSize> read{};
  read.at(kMiddle - 1) = read.at(kMiddle) = true;
  Network middle;
  for (std::size_t i = sort.count; i-- > 0;) {
    CompareExchange step = sort.pairs.at(i);
    step.keeps_low = read.at(step.low);
    step.keeps_high = read.at(step.high);
    if (!step.keeps_low && !step.keeps_high) continue;
    read.at(step.low) = read.at(step.high) = true;
    middle.pairs.at(middle.count++) = step;
  }
  std::reverse(middle.pairs.begin(), middle.pairs.begin() + middle.count);  // back in order
  return middle;
}
constexpr Network kMiddleNetwork = middle_network();
static_assert(merge_sort_network().count == kNetworkPairs && kMiddleNetwork.count == 157);

// (low, high) = (low < high ? low : high, low < high ? high : low), lane by lane, each only
// where the step keeps it. minps(a, b) and maxps(b, a) are exactly those selections, NaN and
// signed zeros included (the second operand wins ties and NaN): one instruction each, where the
// plain x86-64 build compiled the comparison and its two selections into seven (SSE2 has no
// blend).
template <CompareExchange kStep>
[[gnu::always_inline]] inline void compare_exchange(Channels* values) {
  Channels& low = values[kStep.low];
  Channels& high = values[kStep.high];
#if defined(__SSE__)
  const __m128 a = __m128(low), b = __m128(high);
  if constexpr (kStep.keeps_low) low = Channels(_mm_min_ps(a, b));
  if constexpr (kStep.keeps_high) high = Channels(_mm_max_ps(b, a));
#else
  const Channels a = low, b = high;
  if constexpr (kStep.keeps_low) low = a < b ? a : b;
  if constexpr (kStep.keeps_high) high = a < b ? b : a;
#endif
}

// Median of n sorted values, value(j) the j-th.
template <class Value>
float median_of_sorted(Value value, int n) {
  return n % 2 == 1 ? value(n / 2) : 0.5f * (value(n / 2 - 1) + value(n / 2));
}

// Per-channel median of values[0, n), 1 <= n <= kMaxObservationsPerVoxel; may reorder them.
// Up to 32 values all three channels go at once through the pruned network of vector min / max
// (kMiddleNetwork): the median by std::nth_element, with branches on the data, mispredicted its
// way to 0.8 us per voxel (3 channels of 30), three quarters of the albedo stage.
Eigen::Vector3f channel_medians(Channels* values, int n) {
  Eigen::Vector3f median;
  if (n <= kNetworkSize) {
    const int below = (kNetworkSize - n) / 2;
    std::fill(values + n, values + n + below, Channels{} - INFINITY);
    std::fill(values + n + below, values + kNetworkSize, Channels{} + INFINITY);
    [&]<std::size_t... kIndex>(std::index_sequence<kIndex...>) {
      (compare_exchange<kMiddleNetwork.pairs[kIndex]>(values), ...);
    }
    (std::make_index_sequence<kMiddleNetwork.count>{});
    // The n values now lie sorted from `below` on, their middle on kMiddle - 1 and kMiddle.
    for (int c = 0; c < 3; ++c)
      median[c] = median_of_sorted([&](int j) { return values[below + j][c]; }, n);
    return median;
  }
  std::array<float, kMaxObservationsPerVoxel> channel;
  for (int c = 0; c < 3; ++c) {
    for (int j = 0; j < n; ++j) channel[j] = values[j][c];
    std::sort(channel.begin(), channel.begin() + n);
    median[c] = median_of_sorted([&](int j) { return channel[j]; }, n);
  }
  return median;
}

}  // namespace

const char* albedo_average_name(AlbedoAverage average) {
  return average == AlbedoAverage::median ? "median" : "mean";
}

AlbedoAverage parse_albedo_average(const std::string& name) {
  for (const AlbedoAverage average : {AlbedoAverage::mean, AlbedoAverage::median})
    if (name == albedo_average_name(average)) return average;
  throw Error("albedo average", name, "must be mean or median");
}

std::optional<DiffuseObservation> observe_diffuse(const Observation* observations, int count,
                                                  const Eigen::Vector3f& position,
                                                  const Eigen::Vector3f& normal,
                                                  const std::vector<render::PointLight>& lights,
                                                  const Eigen::Vector3f& ks, float alpha,
                                                  AlbedoAverage average, float saturated_radiance,
                                                  const PointLighting& lighting) {
  // The observations seen from above the surface: their colours, and their directions as
  // arrays, for the batched lobe.
  std::array<Eigen::Vector3f, kMaxObservationsPerVoxel> colour;
  std::array<float, kMaxObservationsPerVoxel> x, y, z;
  std::array<int, kMaxObservationsPerVoxel> slot;
  int used = 0;
  // Clipped observations only where every one is: a clipped channel bounds the radiance from
  // below, so its eq. (7) albedo is too dark (by the clipped highlight's part, too).
  bool only_clipped = false;
  for (const bool take_clipped : {false, true}) {
    only_clipped = take_clipped;
    for (int k = 0; k < std::min(count, kMaxObservationsPerVoxel); ++k) {
      const Eigen::Vector3f direction = observations[k].direction();
      if (!(normal.dot(direction) > 0.0f)) continue;
      const Eigen::Vector3f seen = observations[k].colour();
      if (!take_clipped && !(seen.maxCoeff() < saturated_radiance)) continue;
      x[used] = direction.x();
      y[used] = direction.y();
      z[used] = direction.z();
      slot[used] = k;
      colour[used++] = seen;
    }
    if (used > 0) break;
  }
  if (used == 0) return std::nullopt;

  // Per observation sum_l exp(gamma_l) / N_l * L_l cos(theta_i,l); each light's incidence is
  // computed once per voxel.
  std::array<Eigen::Vector3f, kMaxObservationsPerVoxel> specular;
  std::fill_n(specular.begin(), used, Eigen::Vector3f::Zero());
  // The indirect light the lobe mirrors: each observation's mirror ray's, or an even sky
  // (PointLighting::mirrored, indirect_radiance).
  if (!lighting.indirect_radiance.isZero() || !lighting.mirrored.empty())
    for (int j = 0; j < used; ++j) {
      const std::size_t k = std::size_t(slot[j]);
      const Eigen::Vector3f& mirrored =
          k < lighting.mirrored.size() && lighting.mirrored[k].allFinite()
              ? lighting.mirrored[k]
              : lighting.indirect_radiance;
      specular[j] =
          mirrored * render::ward_lobe_albedo(normal.dot(Eigen::Vector3f(x[j], y[j], z[j])), alpha);
    }
  std::array<float, kMaxObservationsPerVoxel> lobe;
  // sum_l L_l cos(theta_i,l) + E_ind, and the same as luminance and with sin: indirect light
  // counts as if it came along the normal, where a normal error changes it least.
  Eigen::Vector3f diffuse = lighting.indirect;
  float cosines = lighting.indirect.mean(), sines = 0;
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const Incidence in = incidence(lights, l, position, normal, lighting);
    if (in.irradiance.isZero()) continue;  // the light is behind the surface or shadowed
    diffuse += in.irradiance;
    const float luminance = in.irradiance.mean();  // L_l cos(theta_i,l), mean over channels
    cosines += luminance;
    sines += luminance / in.cosine * std::sqrt(std::max(0.0f, 1 - in.cosine * in.cosine));
    render::ward_specular_lobes(normal, in.direction, {x.data(), y.data(), z.data()}, used, alpha,
                                lobe.data());
    for (int j = 0; j < used; ++j) specular[j] += in.irradiance * lobe[j];
  }
  // Each observation's radiance less its specular term, per channel.
  DiffuseObservation observed{.irradiance = diffuse,
                              .cosines = cosines,
                              .sines = sines,
                              .indirect = lighting.indirect.mean(),
                              .lower_bound = only_clipped};
  std::array<Channels, std::max(kMaxObservationsPerVoxel, kNetworkSize)> values;
  for (int j = 0; j < used; ++j) {
    values[j] = Channels{};
    for (int c = 0; c < 3; ++c) values[j][c] = colour[j][c] - ks[c] * specular[j][c];
  }
  if (used >= kMinScatterObservations) {
    std::array<float, kMaxObservationsPerVoxel> luminance;
    for (int j = 0; j < used; ++j)
      luminance[std::size_t(j)] = (values[j][0] + values[j][1] + values[j][2]) / 3;
    const std::span<float> sample(luminance.data(), std::size_t(used));
    const float median = median_in_place(sample);
    if (median > 0)
      observed.radiance_error =
          robust_spread_in_place(sample, median) / (median * std::sqrt(float(used)));
  }
  if (average == AlbedoAverage::median) {
    observed.radiance = channel_medians(values.data(), used);
  } else {
    const Channels sum = std::accumulate(values.begin(), values.begin() + used, Channels{});
    observed.radiance = Eigen::Vector3f(sum[0], sum[1], sum[2]) / float(used);
  }
  return observed;
}

std::optional<RefinedAlbedo> solve_albedo(const DiffuseObservation& observed,
                                          const Eigen::Vector3f& unseen) {
  const Eigen::Vector3f irradiance = observed.irradiance + unseen;
  if (irradiance.minCoeff() <= 1e-12f) return std::nullopt;
  const float cosines = observed.cosines + unseen.mean();
  RefinedAlbedo refined;
  refined.kd = float(M_PI) * observed.radiance.cwiseQuotient(irradiance);  // eq. (7)
  refined.light_tangent = observed.sines / cosines;
  refined.indirect_share = observed.indirect / cosines;
  refined.lower_bound = observed.lower_bound;
  refined.radiance_error = observed.radiance_error;
  return refined;
}

float indirect_scale_sample(const DiffuseObservation& observed, const Eigen::Vector3f& gathered,
                            float reference) {
  if (observed.cosines > observed.indirect || observed.lower_bound || !(reference > 0) ||
      !(gathered.minCoeff() > 0))
    return NAN;
  return (float(M_PI) * observed.radiance.cwiseQuotient(gathered)).maxCoeff() / reference;
}

Eigen::Vector3f shrink_albedo(const Eigen::Vector3f& kd, float reference, float error,
                              float spread) {
  const float brightness = kd.maxCoeff();
  if (!(error > 0) || !std::isfinite(spread) || !(reference > 0) || !(brightness > 0)) return kd;
  const float weight = spread * spread / (spread * spread + error * error);
  return (kd * std::pow(reference / brightness, 1 - weight)).cwiseMin(1.0f);
}

}  // namespace glint::reflectance
