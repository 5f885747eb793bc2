#pragma once
// How a near-field point light reaches a surface point (paper 1 eq. (6)): the unit direction to
// the light and L_l cos(theta_i) = intensity cos(theta_i) / r^2, zero when the light is behind
// the surface. Shared by the albedo refinement, the specular lobe fit and the HemiCNN's
// reflectance input.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "render/scene.h"

namespace glint::reflectance {

struct Incidence {
  Eigen::Vector3f direction = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f irradiance = Eigen::Vector3f::Zero();
  float cosine = 0.0f;
};

inline Incidence incidence(const render::PointLight& light, const Eigen::Vector3f& position,
                           const Eigen::Vector3f& normal) {
  const Eigen::Vector3f to_light = light.position.cast<float>() - position;
  const float distance2 = to_light.squaredNorm();
  if (distance2 <= 0.0f) return {};
  const Eigen::Vector3f wi = to_light / std::sqrt(distance2);
  const float cos_i = normal.dot(wi);
  if (cos_i <= 0.0f) return {wi, Eigen::Vector3f::Zero(), 0.0f};
  return {wi, light.intensity * (cos_i / distance2), cos_i};
}

// What reaches one surface point besides the unoccluded point lights: which lights its shadow
// rays found unblocked (bit l for lights[l]; lights from kMaxShadowedLights on are never
// shadowed) and the indirect irradiance gathered from the surfaces around it
// (reflectance/light_transport.h). The default is the paper's image model: every light reaches,
// nothing else does.
using LightMask = std::uint32_t;
inline constexpr int kMaxShadowedLights = 32;
inline constexpr LightMask kAllLights = ~LightMask{0};
struct PointLighting {
  LightMask lit = kAllLights;
  Eigen::Vector3f indirect = Eigen::Vector3f::Zero();
  // The indirect radiance the specular lobe reflects (ks times it times the lobe's albedo;
  // LightTransportParams::indirect_specular): the gathered light as an even sky, or, for a
  // re-rendered pixel, what its lobe rays met. Zero: the specular reflection of indirect light
  // neglected.
  Eigen::Vector3f indirect_radiance = Eigen::Vector3f::Zero();
  // Per stored observation of the voxel (by slot), the radiance its lobe ray met
  // (IndirectSpecular::mirror), NaN where unknown (indirect_radiance stands in); empty: every
  // observation mirrors indirect_radiance.
  std::span<const Eigen::Vector3f> mirrored{};
  // The share of the reaching lights' direct light that the point's observations showed
  // (ObservationGrid::light_shortfall): below 1 in a shadow the fused geometry cannot cast. Only
  // re-renderings (ward_shading()) use it; the albedo refinement is what measures it.
  float direct_share = 1;
  bool reaches(std::size_t light) const {
    return light >= std::size_t(kMaxShadowedLights) || (lit >> light & 1u);
  }
};

// incidence() for lights[l], zero where `lighting` has it shadowed.
inline Incidence incidence(const std::vector<render::PointLight>& lights, std::size_t l,
                           const Eigen::Vector3f& position, const Eigen::Vector3f& normal,
                           const PointLighting& lighting) {
  if (!lighting.reaches(l)) return {};
  return incidence(lights[l], position, normal);
}

// The irradiance share below which reflectance_scale floors a point's irradiance: a tenth of
// what its lights would give it head-on (cos 84 deg), so that grazing and back-lit points'
// radiances are amplified at most tenfold over a head-on lit one's.
inline constexpr float kMinIrradianceShare = 0.1f;

// pi / E per channel, E = sum_l L_l cos(theta_i,l) the irradiance at a surface point from the
// lights `lighting` lets reach it, plus its indirect irradiance, floored at kMinIrradianceShare
// of sum_l L_l over all lights: radiance times this is the point's apparent reflectance, where a
// Lambertian surface shows its albedo kd (eq. (6) with ks = 0) whatever the lights. 0 in a
// channel no light emits.
inline Eigen::Vector3f reflectance_scale(const std::vector<render::PointLight>& lights,
                                         const Eigen::Vector3f& position,
                                         const Eigen::Vector3f& normal,
                                         const PointLighting& lighting = {}) {
  Eigen::Vector3f irradiance = lighting.indirect, head_on = Eigen::Vector3f::Zero();
  for (std::size_t l = 0; l < lights.size(); ++l) {
    irradiance += incidence(lights, l, position, normal, lighting).irradiance;
    const float distance2 = (lights[l].position.cast<float>() - position).squaredNorm();
    if (distance2 > 0.0f) head_on += lights[l].intensity / distance2;
  }
  Eigen::Vector3f scale;
  for (int c = 0; c < 3; ++c) {
    const float floored = std::max(irradiance[c], kMinIrradianceShare * head_on[c]);
    scale[c] = floored > 0.0f ? std::numbers::pi_v<float> / floored : 0.0f;
  }
  return scale;
}

}  // namespace glint::reflectance
