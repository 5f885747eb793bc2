#include "reflectance/albedo_refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "core/error.h"
#include "reflectance/light_incidence.h"

namespace glint::reflectance {
namespace {

// Median of values[0, n), n >= 1; reorders them.
float median(float* values, int n) {
  const int middle = n / 2;
  std::nth_element(values, values + middle, values + n);
  if (n % 2 == 1) return values[middle];
  return 0.5f * (values[middle] + *std::max_element(values, values + middle));
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

std::optional<RefinedAlbedo> refine_albedo(const Observation* observations, int count,
                                           const Eigen::Vector3f& position,
                                           const Eigen::Vector3f& normal,
                                           const std::vector<render::PointLight>& lights,
                                           const Eigen::Vector3f& ks, float alpha,
                                           AlbedoAverage average) {
  std::array<const Observation*, kMaxObservationsPerVoxel> seen;  // from above the surface
  // Their directions as arrays, for the batched lobe.
  std::array<float, kMaxObservationsPerVoxel> x, y, z;
  int used = 0;
  for (int k = 0; k < std::min(count, kMaxObservationsPerVoxel); ++k) {
    const Eigen::Vector3f& direction = observations[k].direction;
    if (!(normal.dot(direction) > 0.0f)) continue;
    x[used] = direction.x();
    y[used] = direction.y();
    z[used] = direction.z();
    seen[used++] = &observations[k];
  }
  if (used == 0) return std::nullopt;

  // Per observation sum_l exp(gamma_l) / N_l * L_l cos(theta_i,l); each light's incidence is
  // computed once per voxel.
  std::array<Eigen::Vector3f, kMaxObservationsPerVoxel> specular;
  std::fill_n(specular.begin(), used, Eigen::Vector3f::Zero());
  std::array<float, kMaxObservationsPerVoxel> lobe;
  Eigen::Vector3f diffuse = Eigen::Vector3f::Zero();  // sum_l L_l cos(theta_i,l)
  float cosines = 0, sines = 0;                       // the same, luminance, and with sin
  for (const render::PointLight& light : lights) {
    const Incidence in = incidence(light, position, normal);
    if (in.irradiance.isZero()) continue;  // the light is behind the surface
    diffuse += in.irradiance;
    const float luminance = in.irradiance.mean();  // L_l cos(theta_i,l), mean over channels
    cosines += luminance;
    sines += luminance / in.cosine * std::sqrt(std::max(0.0f, 1 - in.cosine * in.cosine));
    render::ward_specular_lobes(normal, in.direction, {x.data(), y.data(), z.data()}, used, alpha,
                                lobe.data());
    for (int j = 0; j < used; ++j) specular[j] += in.irradiance * lobe[j];
  }
  if (diffuse.minCoeff() <= 1e-12f) return std::nullopt;

  // Eq. (7) per observation and channel.
  RefinedAlbedo refined;
  refined.light_cosine = cosines / std::sqrt(cosines * cosines + sines * sines);
  Eigen::Vector3f& kd = refined.kd;
  std::array<float, kMaxObservationsPerVoxel> values;
  for (int c = 0; c < 3; ++c) {
    for (int j = 0; j < used; ++j)
      values[j] = float(M_PI) * (seen[j]->colour[c] - ks[c] * specular[j][c]) / diffuse[c];
    kd[c] = average == AlbedoAverage::median
                ? median(values.data(), used)
                : std::accumulate(values.begin(), values.begin() + used, 0.0f) / float(used);
  }
  return refined;
}

}  // namespace glint::reflectance
