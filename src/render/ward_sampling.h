#pragma once
// Importance sampling of the isotropic Ward BRDF (render/ward.h) for the path tracer:
//  - the specular lobe by Walter's half-vector sampling ("Notes on the Ward BRDF", 2005):
//      tan^2(theta_h) = -alpha^2 ln(u1),  phi_h = 2 pi u2,  wi = reflect(wo, h),
//      pdf(wi) = exp(-tan^2(theta_h) / alpha^2) / (4 pi alpha^2 (h.wo) cos^3(theta_h))   (eq. 9)
//    the density of h (the lobe's own normalisation, exact) over the Jacobian 4 (h.wo);
//  - the diffuse part by cosine-weighted hemisphere sampling, pdf cos(theta_i) / pi;
//  - the two mixed, one of them chosen per sample by its share of the mean albedo
//    (mean ks / (mean kd + mean ks)), with the mixture's pdf in the weight (one-sample balance
//    heuristic), so a sample is unbiased whichever lobe produced it.
// Directions are unit vectors pointing away from the surface, n the unit shading normal. All
// maths is inline and allocation-free so a CUDA kernel could call it.
#include <Eigen/Core>
#include <cmath>

#include "render/ward.h"

namespace glint::render {

// Two unit tangents completing unit n to a right-handed frame (Duff et al. 2017, branchless).
inline void tangent_frame(const Eigen::Vector3f& n, Eigen::Vector3f& t, Eigen::Vector3f& b) {
  const float sign = std::copysign(1.0f, n.z());
  const float a = -1.0f / (sign + n.z());
  const float c = n.x() * n.y() * a;
  t = {1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x()};
  b = {c, sign + n.y() * n.y() * a, -n.y()};
}

// The specular lobe's pdf of wi given wo (eq. 9 above), per steradian; 0 when the half vector
// is not on the normal's side.
inline float ward_specular_pdf(const Eigen::Vector3f& n, const Eigen::Vector3f& wi,
                               const Eigen::Vector3f& wo, float alpha) {
  const Eigen::Vector3f sum = wi + wo;
  const float length = sum.norm();
  if (!(length > 0.0f)) return 0.0f;
  const Eigen::Vector3f h = sum / length;
  const float cos_h = n.dot(h), h_dot_wo = h.dot(wo);
  if (cos_h <= 0.0f || h_dot_wo <= 0.0f) return 0.0f;
  const float a = std::max(alpha, kMinWardAlpha);
  const float tan2_h = (1.0f - cos_h * cos_h) / (cos_h * cos_h);
  return std::exp(-tan2_h / (a * a)) /
         (4.0f * float(M_PI) * a * a * h_dot_wo * cos_h * cos_h * cos_h);
}

// Half vector drawn from the lobe's density of h from u1, u2 in [0, 1).
inline Eigen::Vector3f sample_ward_half_vector(const Eigen::Vector3f& n, float alpha, float u1,
                                               float u2) {
  const float a = std::max(alpha, kMinWardAlpha);
  const float tan2_h = -a * a * std::log(1.0f - u1);  // 1 - u1 in (0, 1]
  const float cos_h = 1.0f / std::sqrt(1.0f + tan2_h);
  const float sin_h = std::sqrt(tan2_h) * cos_h;
  const float phi = 2.0f * float(M_PI) * u2;
  Eigen::Vector3f t, b;
  tangent_frame(n, t, b);
  return (sin_h * std::cos(phi)) * t + (sin_h * std::sin(phi)) * b + cos_h * n;
}

// Share of the specular lobe in the mixture: its part of the mean albedo (0 when black).
inline float ward_specular_share(const WardMaterial& m) {
  const float kd = m.kd.mean(), ks = m.ks.mean();
  return kd + ks > 0.0f ? ks / (kd + ks) : 0.0f;
}

// The mixture's pdf of wi given wo: what sample_ward_brdf draws from.
inline float ward_brdf_pdf(const WardMaterial& m, const Eigen::Vector3f& n,
                           const Eigen::Vector3f& wi, const Eigen::Vector3f& wo) {
  const float share = ward_specular_share(m);
  const float cos_i = n.dot(wi);
  const float diffuse = cos_i > 0.0f ? cos_i / float(M_PI) : 0.0f;
  const float specular = share > 0.0f ? ward_specular_pdf(n, wi, wo, m.alpha) : 0.0f;
  return share * specular + (1.0f - share) * diffuse;
}

struct BrdfSample {
  Eigen::Vector3f direction = Eigen::Vector3f::Zero();  // wi, unit
  Eigen::Vector3f weight = Eigen::Vector3f::Zero();     // f(wi, wo) cos(theta_i) / pdf(wi)
  float pdf = 0;                                        // 0: no direction (end the path)
};

// One direction from the mixture, from three uniform numbers in [0, 1): u_lobe picks the lobe,
// u1 and u2 place the direction. Returns pdf 0 for a black material, a direction below the
// shading normal (the lobe's tail past the horizon), or wo below the surface.
inline BrdfSample sample_ward_brdf(const WardMaterial& m, const Eigen::Vector3f& n,
                                   const Eigen::Vector3f& wo, float u_lobe, float u1, float u2) {
  BrdfSample sample;
  if (n.dot(wo) <= 0.0f || (m.kd.mean() + m.ks.mean()) <= 0.0f) return sample;
  if (u_lobe < ward_specular_share(m)) {
    const Eigen::Vector3f h = sample_ward_half_vector(n, m.alpha, u1, u2);
    sample.direction = (2.0f * wo.dot(h)) * h - wo;
  } else {
    const float radius = std::sqrt(u1), phi = 2.0f * float(M_PI) * u2;
    Eigen::Vector3f t, b;
    tangent_frame(n, t, b);
    sample.direction = (radius * std::cos(phi)) * t + (radius * std::sin(phi)) * b +
                       std::sqrt(std::max(0.0f, 1.0f - u1)) * n;
  }
  const float cos_i = n.dot(sample.direction);
  if (cos_i <= 0.0f) return sample;
  const float pdf = ward_brdf_pdf(m, n, sample.direction, wo);
  if (!(pdf > 0.0f)) return sample;
  sample.pdf = pdf;
  sample.weight = ward_brdf(m, n, sample.direction, wo) * (cos_i / pdf);
  return sample;
}

}  // namespace glint::render
