#include "render/ward.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

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

TEST(Ward, LobeAlbedoUnderAnEvenSkyFallsAsTheViewTiltsAndTheLobeWidens) {
  // Midpoint rule in cos^2(theta_i) and azimuth: cos(theta_i) d(omega) = d(cos^2) d(phi) / 2.
  constexpr int kRings = 2000, kSectors = 360;
  for (const float alpha : {0.05f, 0.1f, 0.2f, 0.3f, 0.5f})
    for (const float view : {0.0f, 0.5236f, 1.0472f}) {  // 0, 30 and 60 degrees
      if (alpha > 0.3f && view > 0.6f) continue;         // the form's stated range
      const Eigen::Vector3f wo = direction(view, 0.0f);
      double integral = 0;
      for (int i = 0; i < kRings; ++i) {
        const float theta = std::acos(std::sqrt((float(i) + 0.5f) / kRings));
        for (int j = 0; j < kSectors; ++j)
          integral += ward_specular_lobe(
              kUp, direction(theta, 2 * float(M_PI) * (float(j) + 0.5f) / kSectors), wo, alpha);
      }
      integral *= M_PI / (double(kRings) * kSectors);
      EXPECT_NEAR(integral, ward_lobe_albedo(wo.z(), alpha), 0.03)
          << "alpha " << alpha << ", view " << view;
    }
  EXPECT_EQ(ward_lobe_albedo(-0.5f, 0.1f), 0.0f);  // seen from below: no lobe
}

TEST(Ward, BatchedLobeMatchesTheScalarOne) {
  // Directions all over the sphere (below the surface and grazing ones included), several
  // roughnesses and a tilted normal; an odd count exercises the vector loop's remainder.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> angle(0, 1);
  const int count = 37;
  std::vector<float> x(count), y(count), z(count), lobe(count);
  const Eigen::Vector3f normal = direction(0.3f, 1.0f);
  for (const float alpha : {0.02f, 0.1f, 0.3f}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3f wi = direction(1.6f * angle(rng), 6.3f * angle(rng));
      for (int j = 0; j < count; ++j) {
        const Eigen::Vector3f wo = direction(3.1f * angle(rng), 6.3f * angle(rng));
        x[j] = wo.x(), y[j] = wo.y(), z[j] = wo.z();
      }
      x[0] = normal.x(), y[0] = normal.y(), z[0] = normal.z();  // the peak when wi = n
      ward_specular_lobes(normal, wi, {x.data(), y.data(), z.data()}, count, alpha, lobe.data());
      for (int j = 0; j < count; ++j) {
        const float expected =
            ward_specular_lobe(normal, wi, Eigen::Vector3f(x[j], y[j], z[j]), alpha);
        // Float rounding (FMA or not) is amplified by 1 / alpha^2 in the exponent and by
        // 1 / sqrt(cos_o) near grazing: agreement to 1e-4 still catches any wrong term.
        ASSERT_NEAR(lobe[j], expected, (1e-4f + 1e-6f / (alpha * alpha)) * expected + 1e-30f)
            << "alpha " << alpha << " trial " << trial << " j " << j;
      }
    }
  }
}

TEST(Ward, RoughnessFactorsAreTheLobesAlphaDependentPart) {
  // exp(-tan2 / alpha^2) / alpha^2 against the library exp, up to exp(-40) and zero beyond.
  const std::vector<float> tan2 = {0.0f, 1e-4f, 0.003f, 0.02f, 0.1f, 0.5f, 2.0f, 3.9f, 4.1f, 50.0f};
  std::vector<float> factor(tan2.size());
  for (const float alpha : {0.02f, 0.1f, 0.3f}) {
    ward_roughness_factors(tan2.data(), int(tan2.size()), alpha, factor.data());
    for (std::size_t j = 0; j < tan2.size(); ++j) {
      const float gamma = -tan2[j] / (alpha * alpha);
      const float expected = gamma < -40.0f ? 0.0f : std::exp(gamma) / (alpha * alpha);
      ASSERT_NEAR(factor[j], expected, 1e-5f * expected) << "alpha " << alpha << " j " << j;
    }
  }
}

}  // namespace
}  // namespace glint::render
