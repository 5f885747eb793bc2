#include "render/perceptual.h"

#include <gtest/gtest.h>

#include <random>

namespace glint::render {
namespace {

TEST(Perceptual, LabOfKnownColours) {
  const Eigen::Vector3f white = linear_rgb_to_lab({1, 1, 1});
  EXPECT_NEAR(white.x(), 100.0f, 0.01f);
  EXPECT_NEAR(white.y(), 0.0f, 0.05f);
  EXPECT_NEAR(white.z(), 0.0f, 0.05f);
  // 18 % grey is L* = 49.5; pure sRGB red is (53.24, 80.09, 67.20).
  EXPECT_NEAR(linear_rgb_to_lab({0.18f, 0.18f, 0.18f}).x(), 49.5f, 0.05f);
  const Eigen::Vector3f red = linear_rgb_to_lab({1, 0, 0});
  EXPECT_NEAR(red.x(), 53.24f, 0.05f);
  EXPECT_NEAR(red.y(), 80.09f, 0.1f);
  EXPECT_NEAR(red.z(), 67.20f, 0.1f);
  EXPECT_NEAR(linear_rgb_to_lab({0, 0, 0}).x(), 0.0f, 1e-4f);
}

TEST(Perceptual, ContrastAndDistinctnessFollowPellacini) {
  WardMaterial m;
  m.kd = {0.0f, 0.2f, 0.6f};
  m.ks = {0.125f, 0.05f, 0.0f};
  m.alpha = 0.15f;
  const PerceptualWard p = to_perceptual(m);
  EXPECT_NEAR(p.c[0], 0.5f, 1e-6f);  // kd = 0: c = cbrt(ks)
  EXPECT_NEAR(p.c[1], std::cbrt(0.15f) - std::cbrt(0.1f), 1e-6f);
  EXPECT_NEAR(p.c[2], 0.0f, 1e-6f);  // ks = 0: no gloss contrast
  EXPECT_NEAR(p.d, 0.85f, 1e-6f);
}

TEST(Perceptual, RoundTripOverTheTrainingRanges) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  for (int i = 0; i < 1000; ++i) {
    WardMaterial m;
    m.kd = {0.01f + 0.89f * u(rng), 0.01f + 0.89f * u(rng), 0.01f + 0.89f * u(rng)};
    for (int c = 0; c < 3; ++c) m.ks[c] = (1 - m.kd[c]) * u(rng) * 0.5f;
    m.alpha = 0.01f + 0.3f * u(rng);
    const WardMaterial back = from_perceptual(to_perceptual(m));
    EXPECT_TRUE(back.kd.isApprox(m.kd, 1e-4f)) << back.kd.transpose() << " vs " << m.kd.transpose();
    EXPECT_LT((back.ks - m.ks).cwiseAbs().maxCoeff(), 1e-5f);
    EXPECT_NEAR(back.alpha, m.alpha, 1e-6f);
  }
  const Eigen::Vector3f lab(62.0f, -20.0f, 35.0f);
  EXPECT_TRUE(linear_rgb_to_lab(lab_to_linear_rgb(lab)).isApprox(lab, 1e-4f));
}

TEST(Perceptual, OutOfGamutColoursGiveNoNegativeAlbedo) {
  // A saturated teal beyond the sRGB gamut: its linear red is negative.
  PerceptualWard p;
  p.lab = {50.0f, -60.0f, -20.0f};
  p.c = {0.1f, 0.1f, 0.1f};
  p.d = 0.9f;
  ASSERT_LT(lab_to_linear_rgb(p.lab).x(), 0.0f);
  const WardMaterial m = from_perceptual(p);
  EXPECT_EQ(m.kd.x(), 0.0f);
  EXPECT_GT(m.kd.y(), 0.0f);
  EXPECT_NEAR(m.ks.x(), 0.001f, 1e-6f);  // kd 0: ks = c^3
}

}  // namespace
}  // namespace glint::render
