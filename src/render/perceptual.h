#pragma once
// The perceptual Ward parametrisation the HemiCNN loss works in (paper 1 eq. 5; Pellacini,
// Ferwerda and Greenberg 2000), per RGB channel as the paper's c_r, c_g, c_b imply:
//   (L, a, b) = CIELAB (D65) of kd, read as linear RGB with sRGB primaries
//   c_i = cbrt(ks_i + kd_i / 2) - cbrt(kd_i / 2)
//   d   = 1 - alpha
// and back. Lab uses L in [0, 100], a and b about [-128, 127].
#include <Eigen/Core>

#include "render/ward.h"

namespace glint::render {

struct PerceptualWard {
  Eigen::Vector3f lab{50.0f, 0.0f, 0.0f};  // CIELAB of kd
  Eigen::Vector3f c{0.0f, 0.0f, 0.0f};     // per-channel contrast of gloss
  float d = 0.9f;                          // distinctness of image, 1 - alpha
};

// Relative luminance Y of linear RGB (sRGB primaries, D65).
inline float luminance(const Eigen::Vector3f& rgb) {
  return 0.2126f * rgb.x() + 0.7152f * rgb.y() + 0.0722f * rgb.z();
}

// Linear RGB (sRGB primaries, D65) <-> CIELAB.
Eigen::Vector3f linear_rgb_to_lab(const Eigen::Vector3f& rgb);
Eigen::Vector3f lab_to_linear_rgb(const Eigen::Vector3f& lab);

PerceptualWard to_perceptual(const WardMaterial& material);
// kd's channels are clamped at 0: a Lab colour outside the sRGB gamut (a network's prediction
// for a saturated surface, e.g. a teal one's red) has a negative linear channel, which no
// surface reflects.
WardMaterial from_perceptual(const PerceptualWard& perceptual);

}  // namespace glint::render
