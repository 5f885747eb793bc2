// Ward -> glTF: the half-vector lobes are normalised, the least-squares fit at known points and
// the closed form beside it, ks -> F0, and the light units against glint's own shading.
#include "gltf/material_conversion.h"

#include <gtest/gtest.h>

#include <cmath>

#include "reflectance/material_maps.h"

namespace glint::gltf {
namespace {

double hemisphere_integral(double (*density)(double, double), double parameter) {
  const int steps = 20000;
  const double step = 0.5 * M_PI / steps;
  double sum = 0;
  for (int i = 0; i < steps; ++i) {
    const double theta = (i + 0.5) * step;
    sum += density(theta, parameter) * std::sin(theta);
  }
  return 2 * M_PI * step * sum;
}

TEST(MaterialConversion, BothLobesIntegrateToOneOverTheHemisphere) {
  for (const double roughness : {0.02, 0.1, 0.3, 0.5}) {
    EXPECT_NEAR(hemisphere_integral(ward_half_vector_density, roughness), 1.0, 1e-3) << roughness;
    EXPECT_NEAR(hemisphere_integral(ggx_half_vector_density, roughness), 1.0, 1e-3) << roughness;
  }
}

TEST(MaterialConversion, GgxEqualsBeckmannAtTheNormalWhenAlphasMatch) {
  // Both peaks are 1 / (pi a^2): the fit differs from a = alpha only through the tails.
  EXPECT_NEAR(ward_half_vector_density(0, 0.2), ggx_half_vector_density(0, 0.2), 1e-9);
}

TEST(MaterialConversion, LeastSquaresFitAtKnownPoints) {
  // The measured optima (docs/benchmarks.md): a / alpha 0.925 at 0.02, 0.924 at 0.1, 0.914 at
  // 0.5; the GGX lobe keeps 18 % of its energy off Ward's (its longer tails) at every alpha.
  const struct { double alpha, ratio; } known[] = {{0.02, 0.925}, {0.1, 0.924}, {0.5, 0.914}};
  for (const auto& [alpha, ratio] : known) {
    const LobeFit fit = fit_ggx_to_ward(alpha);
    EXPECT_NEAR(fit.a / alpha, ratio, 2e-3) << alpha;
    EXPECT_NEAR(fit.total_variation, 0.183, 3e-3) << alpha;
    // The optimum beats its neighbours.
    EXPECT_LT(fit.total_variation, lobe_total_variation(alpha, alpha));
  }
}

TEST(MaterialConversion, ClosedFormStaysWithinOnePercentOfTheOptimum) {
  for (double alpha = 0.02; alpha <= 0.5001; alpha += 0.04) {
    const double a = ward_alpha_to_roughness(float(alpha)) * ward_alpha_to_roughness(float(alpha));
    const LobeFit fit = fit_ggx_to_ward(alpha);
    EXPECT_NEAR(a / fit.a, 1.0, 0.01) << alpha;
    EXPECT_LT(lobe_total_variation(alpha, a) - fit.total_variation, 1e-3) << alpha;
  }
  EXPECT_NEAR(ward_alpha_to_roughness(0.1f), std::sqrt(0.0918f), 1e-6);
  EXPECT_EQ(ward_alpha_to_roughness(0.0f), 0.0f);
  EXPECT_EQ(ward_alpha_to_roughness(5.0f), 1.0f);  // clamped to glTF's range
}

TEST(MaterialConversion, SpecularColourMakesF0EqualKs) {
  const Eigen::Vector3f ks(0.02f, 0.04f, 0.08f);
  EXPECT_TRUE((kDielectricF0 * specular_color_factor(ks)).isApprox(ks));
  EXPECT_TRUE(specular_color_factor({-1, 0, 0}).isZero());
}

TEST(MaterialConversion, PunctualLightReproducesGlintsIrradiance) {
  // A surface 2 m below a light, facing it: glint's shading gives diffuse = I / d^2;
  // KHR_lights_punctual gives color * intensity / d^2 (candela -> lux at normal incidence).
  render::PointLight light;
  light.position = {0, 2, 0};
  light.intensity = {6.0f, 3.0f, 1.5f};
  const Eigen::Vector3f p(0, 0, 0), n(0, 1, 0), eye(1, 1, 0);
  const Eigen::Vector3f glint = reflectance::ward_shading(0.1f, p, n, eye, {light}).diffuse;
  const PunctualLight punctual = punctual_light(light.intensity);
  const float d2 = 4;
  EXPECT_TRUE(glint.isApprox(punctual.color * punctual.intensity / d2, 1e-6f));
  EXPECT_FLOAT_EQ(punctual.intensity, 6.0f);
  EXPECT_FLOAT_EQ(punctual.color.maxCoeff(), 1.0f);
  // A dark light is white at 0 cd (glTF's colour must stay in [0, 1]).
  const PunctualLight dark = punctual_light(Eigen::Vector3f::Zero());
  EXPECT_EQ(dark.intensity, 0.0f);
  EXPECT_TRUE(dark.color.isOnes());
}

}  // namespace
}  // namespace glint::gltf
