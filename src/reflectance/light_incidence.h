#pragma once
// How a near-field point light reaches a surface point (paper 1 eq. (6)): the unit direction to
// the light and L_l cos(theta_i) = intensity cos(theta_i) / r^2, zero when the light is behind
// the surface. Shared by the albedo refinement and the specular lobe fit.
#include <Eigen/Core>
#include <cmath>

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

}  // namespace glint::reflectance
