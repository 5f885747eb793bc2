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
  // Eq. (7) is linear in B_k and in the specular sum, so its mean over the observations is
  // eq. (7) of the mean colour and the mean specular sum: each light's incidence is computed
  // once per voxel, not once per observation.
  Eigen::Vector3f colour_sum = Eigen::Vector3f::Zero();
  int used = 0;
  for (int k = 0; k < count; ++k)
    if (normal.dot(observations[k].direction) > 0.0f) {
      colour_sum += observations[k].colour;
      ++used;
    }
  if (used == 0) return std::nullopt;

  Eigen::Vector3f diffuse = Eigen::Vector3f::Zero();   // sum_l L_l cos
  Eigen::Vector3f specular = Eigen::Vector3f::Zero();  // sum_k sum_l exp(gamma)/N L_l cos
  for (const render::PointLight& light : lights) {
    const Incidence in = incidence(light, position, normal);
    if (in.irradiance.isZero()) continue;  // the light is behind the surface
    diffuse += in.irradiance;
    float lobe_sum = 0.0f;
    for (int k = 0; k < count; ++k)
      if (normal.dot(observations[k].direction) > 0.0f)
        lobe_sum +=
            render::ward_specular_lobe(normal, in.direction, observations[k].direction, alpha);
    specular += in.irradiance * lobe_sum;
  }
  if (diffuse.minCoeff() <= 1e-12f) return std::nullopt;
  return float(M_PI) * (colour_sum - ks.cwiseProduct(specular)).cwiseQuotient(diffuse) /
         float(used);
}

}  // namespace glint::reflectance
