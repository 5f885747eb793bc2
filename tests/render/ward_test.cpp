#include "render/ward.h"

#include <gtest/gtest.h>

#include <random>

namespace glint::render {
namespace {

const Eigen::Vector3f kUp(0, 0, 1);

Eigen::Vector3f direction(float theta, float phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

TEST(Ward, MirrorConfigurationPeaksAtOneOverFourPiAlphaSquared) {
  // wi = wo = n: theta_h = 0, so exp(gamma) = 1 and the lobe is 1 / (4 pi alpha^2).
  for (float alpha : {0.05f, 0.1f, 0.3f})
    EXPECT_NEAR(ward_specular_lobe(kUp, kUp, kUp, alpha), 1.0f / (4 * M_PI * alpha * alpha),
                1e-4f / (alpha * alpha));
}

TEST(Ward, MatchesTheFormulaAtAnOffSpecularPair) {
  const Eigen::Vector3f wi = direction(0.5f, 0.0f), wo = direction(0.3f, 2.0f);
  const float alpha = 0.2f;
  const Eigen::Vector3f h = (wi + wo).normalized();
  const double theta_h = std::acos(double(h.z()));
  const double expected = std::exp(-std::tan(theta_h) * std::tan(theta_h) / (alpha * alpha)) /
                          (4 * M_PI * alpha * alpha * std::sqrt(double(wi.z()) * wo.z()));
  WardMaterial m;
  m.kd = {0.2f, 0.3f, 0.4f};
  m.ks = {0.1f, 0.2f, 0.3f};
  m.alpha = alpha;
  const Eigen::Vector3f f = ward_brdf(m, kUp, wi, wo);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(f[c], m.kd[c] / M_PI + m.ks[c] * expected, 1e-5 * (1 + f[c]));
}

TEST(Ward, IsReciprocalAndZeroBelowTheSurface) {
  WardMaterial m;
  m.ks = {0.3f, 0.3f, 0.3f};
  const Eigen::Vector3f a = direction(0.7f, 0.4f), b = direction(0.2f, 3.0f);
  EXPECT_TRUE(ward_brdf(m, kUp, a, b).isApprox(ward_brdf(m, kUp, b, a), 1e-6f));
  EXPECT_EQ(ward_brdf(m, kUp, -a, b), Eigen::Vector3f::Zero());
  EXPECT_EQ(ward_brdf(m, kUp, a, -b), Eigen::Vector3f::Zero());
}

TEST(Ward, GuardsGrazingAnglesAndZeroRoughness) {
  const Eigen::Vector3f grazing = direction(float(M_PI / 2) - 1e-6f, 0.0f);
  EXPECT_EQ(ward_specular_lobe(kUp, grazing, kUp, 0.1f), 0.0f);
  const float sharp = ward_specular_lobe(kUp, kUp, kUp, 0.0f);
  EXPECT_TRUE(std::isfinite(sharp));
  EXPECT_NEAR(sharp, 1.0f / (4 * M_PI * kMinWardAlpha * kMinWardAlpha), sharp * 1e-4f);
  EXPECT_EQ(ward_specular_lobe(kUp, direction(0.3f, 0.0f), direction(0.5f, float(M_PI)), 0.0f),
            0.0f);  // off the mirror direction a vanishing lobe underflows to 0, not NaN
}

TEST(Ward, DirectionalAlbedoIsKdPlusAboutKs) {
  // Monte Carlo over the hemisphere with cosine-weighted samples: integral of f cos = kd + ks*~1
  // (Ward's normalisation is accurate for small alpha at normal view).
  WardMaterial m;
  m.kd = {0.4f, 0.4f, 0.4f};
  m.ks = {0.0f, 0.2f, 0.2f};
  m.alpha = 0.1f;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(0, 1);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const int samples = 400000;
  for (int i = 0; i < samples; ++i) {
    const float r = std::sqrt(uniform(rng)), phi = 2 * float(M_PI) * uniform(rng);
    const Eigen::Vector3f wi(r * std::cos(phi), r * std::sin(phi), std::sqrt(1 - r * r));
    sum += (ward_brdf(m, kUp, wi, kUp) * float(M_PI)).cast<double>();  // f cos / pdf, pdf = cos/pi
  }
  const Eigen::Vector3d albedo = sum / samples;
  EXPECT_NEAR(albedo[0], 0.4, 0.01);
  EXPECT_NEAR(albedo[1], 0.6, 0.02);
}

}  // namespace
}  // namespace glint::render
