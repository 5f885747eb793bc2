#include "reflectance/albedo_refinement.h"

namespace glint::reflectance {
namespace {

// Unit direction to the light and L_l cos(theta_i) (zero when the light is behind the surface).
struct Incidence {
  Eigen::Vector3f direction;
  Eigen::Vector3f irradiance;
};

Incidence incidence(const render::PointLight& light, const Eigen::Vector3f& position,
                    const Eigen::Vector3f& normal) {
  const Eigen::Vector3f to_light = light.position.cast<float>() - position;
  const float distance2 = to_light.squaredNorm();
  if (distance2 <= 0.0f) return {Eigen::Vector3f::UnitZ(), Eigen::Vector3f::Zero()};
  const Eigen::Vector3f wi = to_light / std::sqrt(distance2);
  const float cos_i = normal.dot(wi);
  if (cos_i <= 0.0f) return {wi, Eigen::Vector3f::Zero()};
  return {wi, light.intensity * (cos_i / distance2)};
}

}  // namespace

std::optional<Eigen::Vector3f> refine_albedo(const Observation* observations, int count,
                                             const Eigen::Vector3f& position,
                                             const Eigen::Vector3f& normal,
                                             const std::vector<render::PointLight>& lights,
                                             const Eigen::Vector3f& ks, float alpha) {
  // The denominator of eq. (7) depends on the lights only, not on the observation.
  Eigen::Vector3f diffuse = Eigen::Vector3f::Zero();
  for (const render::PointLight& light : lights)
    diffuse += incidence(light, position, normal).irradiance;
  if (diffuse.minCoeff() <= 1e-12f) return std::nullopt;

  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  int used = 0;
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector3f& wo = observations[k].direction;
    if (normal.dot(wo) <= 0.0f) continue;
    Eigen::Vector3f specular = Eigen::Vector3f::Zero();
    for (const render::PointLight& light : lights) {
      const Incidence in = incidence(light, position, normal);
      specular += in.irradiance * render::ward_specular_lobe(normal, in.direction, wo, alpha);
    }
    sum +=
        float(M_PI) * (observations[k].colour - ks.cwiseProduct(specular)).cwiseQuotient(diffuse);
    ++used;
  }
  if (used == 0) return std::nullopt;
  return sum / float(used);
}

}  // namespace glint::reflectance
