#pragma once
// glint's reflectance model in glTF's terms (docs/reflectance.md, "Export"):
// - Ward's roughness alpha -> glTF's metallic-roughness `roughness` (GGX with a = roughness^2),
//   from a least-squares fit of the GGX half-vector distribution to Ward's;
// - the specular albedo ks -> KHR_materials_specular's F0 colour;
// - a point light's intensity in glint's units -> KHR_lights_punctual's colour and candela.
#include <Eigen/Core>

namespace glint::gltf {

// Ward's lobe as a distribution of half vectors over the hemisphere, in projected form
// (integrates to 1 over solid angle; Walter 2005: exp(-tan^2 th / alpha^2) / (pi alpha^2
// cos^3 th), which is Beckmann's D(h) cos th with m = alpha).
double ward_half_vector_density(double theta_h, double alpha);
// GGX's (Trowbridge-Reitz, glTF 2.0 Appendix B) D(h) cos th for a = roughness^2, same
// normalisation.
double ggx_half_vector_density(double theta_h, double a);

struct LobeFit {
  double a = 0;              // GGX's alpha (roughness^2) minimising the squared difference
  double squared_error = 0;  // integral over the hemisphere of (ward - ggx)^2 at `a`
  // Total-variation distance 0.5 * integral |ward - ggx| d omega at `a`: the share of the lobe's
  // energy in the wrong directions, in [0, 1].
  double total_variation = 0;
};
// The least-squares fit for one Ward alpha: golden-section search over a in [alpha/4, 4 alpha]
// of the integral of (ward - ggx)^2 over the hemisphere (4096-point midpoint rule in theta).
LobeFit fit_ggx_to_ward(double alpha);
// Total-variation distance between Ward(alpha) and GGX(a), as LobeFit::total_variation.
double lobe_total_variation(double alpha, double a);

// The closed form the exporter uses: a = kWardToGgx * alpha, roughness = sqrt(a), clamped to
// [0, 1]. The per-alpha optimum a / alpha runs from 0.925 (alpha 0.02) to 0.914 (alpha 0.5);
// 0.918 is the least-squares slope through the origin of the optima at alpha = 0.02, 0.03, ...,
// 0.5 (bench/gltf/roughness_fit.cpp, docs/decisions.md).
inline constexpr double kWardToGgx = 0.918;
float ward_alpha_to_roughness(float alpha);

// KHR_materials_specular: F0 = min(0.04 * specularColorFactor, 1) * specularFactor for the
// default ior 1.5; Ward's ks is the lobe's albedo, which a GGX lobe reaches at F0 (its
// directional albedo at normal incidence), so specularColorFactor = ks / 0.04,
// specularFactor = 1.
inline constexpr float kDielectricF0 = 0.04f;
Eigen::Vector3f specular_color_factor(const Eigen::Vector3f& ks);

// KHR_lights_punctual: a point light of `intensity` (candela) and linear `color` lights a
// surface at distance d facing it with color * intensity / d^2 (lux); glint's light of RGB
// intensity I gives I / d^2 (reflectance/light_estimation.h), so color * intensity = I:
// intensity = max channel, color = I / max (white and 0 for a dark light).
struct PunctualLight {
  Eigen::Vector3f color{1, 1, 1};
  float intensity = 0;  // candela per unit of glint's intensity
};
PunctualLight punctual_light(const Eigen::Vector3f& intensity);

}  // namespace glint::gltf
