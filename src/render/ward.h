#pragma once
// Isotropic Ward BRDF (Ward 1992), as used by the reflectance pipeline (paper 1, eqs 2-4):
//   f(wi, wo) = kd/pi + ks * exp(-tan^2(theta_h) / alpha^2) / (4 pi alpha^2 sqrt(cos_i cos_o))
// kd and ks are linear RGB albedos (physically plausible when kd + ks <= 1 per channel), alpha
// the roughness (Ward suits alpha up to ~0.3). Directions are unit vectors pointing away from
// the surface; all maths is inline so a CUDA kernel can call it.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

namespace glint::render {

struct WardMaterial {
  Eigen::Vector3f kd{0.5f, 0.5f, 0.5f};  // diffuse albedo, linear RGB
  Eigen::Vector3f ks{0.0f, 0.0f, 0.0f};  // specular albedo, linear RGB
  float alpha = 0.1f;                    // roughness, > 0
};

// Smallest roughness evaluated: below it the lobe is narrower than float precision resolves.
inline constexpr float kMinWardAlpha = 1e-3f;
// Cosines below this count as grazing: the specular term's 1/sqrt(cos_i cos_o) diverges there.
inline constexpr float kGrazingCosine = 1e-4f;

// tan^2(theta_h), theta_h the angle between unit normal n and the half vector of unit wi, wo;
// +infinity when the half vector is perpendicular to n.
inline float ward_half_angle_tan2(const Eigen::Vector3f& n, const Eigen::Vector3f& wi,
                                  const Eigen::Vector3f& wo) {
  const Eigen::Vector3f h = wi + wo;  // unnormalised half vector
  const float cos_h2 = std::min(1.0f, n.dot(h) * n.dot(h) / h.squaredNorm());
  if (cos_h2 <= 0.0f) return std::numeric_limits<float>::infinity();
  return (1.0f - cos_h2) / cos_h2;
}

// The specular lobe's scalar factor exp(gamma) / N (eqs 3-4) for unit normal n and unit wi, wo
// on the normal's side; 0 at grazing angles or when either direction is below the surface.
inline float ward_specular_lobe(const Eigen::Vector3f& n, const Eigen::Vector3f& wi,
                                const Eigen::Vector3f& wo, float alpha) {
  const float cos_i = n.dot(wi), cos_o = n.dot(wo);
  if (cos_i <= kGrazingCosine || cos_o <= kGrazingCosine) return 0.0f;
  const float a = std::max(alpha, kMinWardAlpha);
  const float gamma = -ward_half_angle_tan2(n, wi, wo) / (a * a);  // eq. (4)
  // exp(-40) / N < 1e-8 even at alpha = kMinWardAlpha and grazing cosines: skip exp and sqrt.
  if (gamma < -40.0f) return 0.0f;
  const float norm = 4.0f * float(M_PI) * a * a * std::sqrt(cos_i * cos_o);  // eq. (3)
  return std::exp(gamma) / norm;
}

// The lobe's directional albedo: the integral over the hemisphere of
// ward_specular_lobe(n, wi, wo, alpha) cos(theta_i), what ks multiplies under an even sky. Eq. (3)
// loses energy as the view tilts and the lobe widens: cos(theta_o) / (1 + 2.88 alpha^2) is within
// 0.03 of the integral for alpha <= 0.3 and views up to 60 degrees off the normal, and for alpha
// 0.5 up to 30 degrees (tests/render/ward_test.cpp).
inline float ward_lobe_albedo(float cos_o, float alpha) {
  return std::max(0.0f, cos_o) / (1 + 2.88f * alpha * alpha);
}

// Directions as three coordinate arrays (structure of arrays), for the batched lobe below.
struct DirectionArrays {
  const float* x;
  const float* y;
  const float* z;
};

// ward_specular_lobe(n, wi, wo[j], alpha) for j < count into lobe[j], as one vectorised loop
// (AVX2 where the CPU has it): the albedo refinement evaluates it for every light and stored
// observation of every voxel it refines. Its exp() is a polynomial good to about 2e-7 relative;
// the values agree with ward_specular_lobe() to float rounding, which tan^2(theta_h) / alpha^2
// and 1 / sqrt(cos_o) amplify (well below 1e-4 + 1e-6 / alpha^2 relative).
void ward_specular_lobes(const Eigen::Vector3f& n, const Eigen::Vector3f& wi, DirectionArrays wo,
                         int count, float alpha, float* lobe);

// exp(-tan2_h[j] / alpha^2) / alpha^2 for j < count into factor[j] (0 below exp(-40)): the part
// of the lobe (eqs 3-4) that depends on alpha, for fits that try many alphas on the same
// directions. Vectorised as ward_specular_lobes().
void ward_roughness_factors(const float* tan2_h, int count, float alpha, float* factor);

// f(wi, wo) per RGB channel, eq. (2); 0 when either direction is below the surface.
inline Eigen::Vector3f ward_brdf(const WardMaterial& m, const Eigen::Vector3f& n,
                                 const Eigen::Vector3f& wi, const Eigen::Vector3f& wo) {
  if (n.dot(wi) <= 0.0f || n.dot(wo) <= 0.0f) return Eigen::Vector3f::Zero();
  return m.kd / float(M_PI) + m.ks * ward_specular_lobe(n, wi, wo, m.alpha);
}

}  // namespace glint::render
