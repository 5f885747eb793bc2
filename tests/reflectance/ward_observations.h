#pragma once
// Synthetic reflectance observations for the tests: the radiance a camera in direction wo sees
// at a surface point under near-field point lights, paper 1 eq. (6), no shadows.
#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "render/scene.h"
#include "render/ward.h"

namespace glint::reflectance::test_support {

inline Eigen::Vector3f observed(const render::WardMaterial& m, const Eigen::Vector3f& position,
                                const Eigen::Vector3f& normal, const Eigen::Vector3f& wo,
                                const std::vector<render::PointLight>& lights) {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  for (const auto& light : lights) {
    const Eigen::Vector3f to_light = light.position.cast<float>() - position;
    const Eigen::Vector3f wi = to_light.normalized();
    sum += render::ward_brdf(m, normal, wi, wo).cwiseProduct(light.intensity) *
           std::max(0.0f, normal.dot(wi)) / to_light.squaredNorm();
  }
  return sum;
}

}  // namespace glint::reflectance::test_support
