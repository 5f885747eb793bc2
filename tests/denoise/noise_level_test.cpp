#include "denoise/noise_level.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "denoise/corruption.h"
#include "image_test_support.h"

namespace glint::denoise {
namespace {

using test::error_of;
using ::testing::HasSubstr;

constexpr NoiseMethod kMethods[] = {NoiseMethod::svd, NoiseMethod::variance};

// 64×64 RGB, flat 0.5 except Gaussian noise (σ = 0.1) in the square [20, 44)².
ImageF flat_with_noisy_square() {
  const ImageF square = test::box_mask(64, 64, 20, 20, 44, 44);
  return add_noise_in_mask(test::constant(64, 64, 3, 0.5f), square, 0.1, 7, false);
}

float largest(const ImageF& image) {
  return *std::max_element(image.values().begin(), image.values().end());
}

TEST(NoiseLevel, ParsesMethodNames) {
  EXPECT_EQ(parse_noise_method("svd"), NoiseMethod::svd);
  EXPECT_EQ(parse_noise_method("var"), NoiseMethod::variance);
  EXPECT_EQ(parse_noise_method("variance"), NoiseMethod::variance);
  const Error e = error_of([] { parse_noise_method("median"); });
  EXPECT_EQ(e.file(), "--method");
  EXPECT_EQ(e.element(), "median");
}

TEST(NoiseLevel, HighOnlyInTheNoisyRegion) {
  const ImageF image = flat_with_noisy_square();
  for (const NoiseMethod method : kMethods) {
    SCOPED_TRACE(static_cast<int>(method));
    const ImageF noise = noise_level(image, {method, 7});
    ASSERT_EQ(noise.width(), 64);
    ASSERT_EQ(noise.height(), 64);
    ASSERT_EQ(noise.channels(), 1);
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        const bool inside = x >= 23 && x < 41 && y >= 23 && y < 41;   // whole patch noisy
        const bool outside = x < 17 || x >= 47 || y < 17 || y >= 47;  // whole patch flat
        if (inside) {
          EXPECT_GT(noise.at(x, y, 0), 0.002f) << x << ", " << y;  // σ² = 0.01
        }
        if (outside) {
          EXPECT_EQ(noise.at(x, y, 0), 0.f) << x << ", " << y;
        }
      }
    }
  }
}

TEST(NoiseLevel, GuidanceIsLowInTheNoisyRegionAndOneOutside) {
  const ImageF image = flat_with_noisy_square();
  for (const NoiseMethod method : kMethods) {
    SCOPED_TRACE(static_cast<int>(method));
    const Guidance guidance = guidance_from_noise(noise_level(image, {method, 7}));
    double inside = 0;
    for (int y = 23; y < 41; ++y) {
      for (int x = 23; x < 41; ++x) inside += guidance.map.at(x, y, 0);
    }
    EXPECT_LT(inside / (18 * 18), 0.5);
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        if (x < 17 || x >= 47 || y < 17 || y >= 47) {
          EXPECT_EQ(guidance.map.at(x, y, 0), 1.f);
        }
      }
    }
  }
}

TEST(NoiseLevel, StepEdgeIsNoiseToTheVarianceButNotToTheSvd) {
  ImageF step(32, 32, 1, 0.2f);
  for (int y = 0; y < 32; ++y) {
    for (int x = 16; x < 32; ++x) step.at(x, y, 0) = 0.8f;
  }
  const ImageF variance = noise_level(step, {NoiseMethod::variance, 7});
  const ImageF svd = noise_level(step, {NoiseMethod::svd, 7});
  EXPECT_NEAR(variance.at(16, 10, 0), 0.36 * (3.0 / 7) * (4.0 / 7), 1e-6);  // p (1 - p) 0.6²
  EXPECT_GT(variance.at(14, 10, 0), 0.05f);
  EXPECT_EQ(variance.at(4, 10, 0), 0.f);
  EXPECT_LT(largest(svd), 1e-6f);
}

TEST(NoiseLevel, LinearRampHasNoSvdNoise) {
  ImageF ramp(40, 30, 3);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      ramp.at(x, y, 0) = 0.01f * x + 0.005f * y;
      ramp.at(x, y, 1) = 0.9f - 0.02f * x;
      ramp.at(x, y, 2) = 0.1f + 0.03f * y;
    }
  }
  EXPECT_LT(largest(noise_level(ramp, {NoiseMethod::svd, 7})), 1e-6f);
  EXPECT_GT(largest(noise_level(ramp, {NoiseMethod::variance, 7})), 1e-3f);
}

// eq. (7)-(12) spelled out with an SVD of each subset's centred points.
double svd_noise_by_definition(const ImageF& image, int cx, int cy, int radius) {
  std::vector<Eigen::Vector3d> patch;
  double mean = 0;
  for (int y = cy - radius; y <= cy + radius; ++y) {
    for (int x = cx - radius; x <= cx + radius; ++x) {
      patch.emplace_back(x - cx, y - cy, image.at(x, y, 0));
      mean += image.at(x, y, 0);
    }
  }
  mean /= static_cast<double>(patch.size());
  double noise = INFINITY;
  for (const bool lower : {true, false}) {
    std::vector<Eigen::Vector3d> subset;
    for (const auto& p : patch) {
      if ((p.z() < mean) == lower) subset.push_back(p);
    }
    Eigen::MatrixXd m(subset.size(), 3);
    for (std::size_t i = 0; i < subset.size(); ++i) m.row(i) = subset[i].transpose();
    m.rowwise() -= m.colwise().mean();
    const double sigma_min = Eigen::JacobiSVD<Eigen::MatrixXd>(m).singularValues()[2];
    noise = std::min(noise, sigma_min * sigma_min / static_cast<double>(subset.size()));
  }
  return noise;
}

TEST(NoiseLevel, SvdMatchesTheDefinitionOnRandomPatches) {
  const ImageF image = test::random_image(20, 20, 1, 3);
  const ImageF noise = noise_level(image, {NoiseMethod::svd, 5});
  for (int y = 2; y < 18; y += 3) {
    for (int x = 2; x < 18; x += 5) {
      EXPECT_NEAR(noise.at(x, y, 0), svd_noise_by_definition(image, x, y, 2), 1e-6)
          << x << ", " << y;
    }
  }
}

TEST(NoiseLevel, BorderPixelsShareTheNearestFullPatch) {
  const ImageF image = test::random_image(16, 12, 2, 5);
  for (const NoiseMethod method : kMethods) {
    const ImageF noise = noise_level(image, {method, 5});
    EXPECT_EQ(noise.at(0, 0, 0), noise.at(2, 2, 0));
    EXPECT_EQ(noise.at(1, 5, 0), noise.at(2, 5, 0));
    EXPECT_EQ(noise.at(15, 11, 0), noise.at(13, 9, 0));
    EXPECT_NE(noise.at(3, 3, 0), noise.at(2, 2, 0));
  }
}

TEST(NoiseLevel, ChannelsCombineByTheirMaximum) {
  const ImageF image = test::random_image(24, 18, 2, 11);
  ImageF first(24, 18, 1), second(24, 18, 1);
  std::copy_n(image.plane(0), image.pixel_count(), first.plane(0));
  std::copy_n(image.plane(1), image.pixel_count(), second.plane(0));
  for (const NoiseMethod method : kMethods) {
    const ImageF both = noise_level(image, {method, 7});
    const ImageF a = noise_level(first, {method, 7}), b = noise_level(second, {method, 7});
    for (std::size_t i = 0; i < both.values().size(); ++i) {
      ASSERT_EQ(both.values()[i], std::max(a.values()[i], b.values()[i]));
    }
  }
}

TEST(NoiseLevel, ImagesSmallerThanThePatchUseAllTheirPixels) {
  const ImageF image = test::random_image(5, 2, 1, 13);
  const ImageF noise = noise_level(image, {NoiseMethod::variance, 7});
  ASSERT_EQ(noise.width(), 5);
  ASSERT_EQ(noise.height(), 2);
  double mean = 0, squares = 0;
  for (const float v : image.values()) mean += v, squares += v * v;
  mean /= 10;
  EXPECT_NEAR(noise.at(4, 1, 0), squares / 10 - mean * mean, 1e-6);
  EXPECT_EQ(noise_level(image, {NoiseMethod::svd, 3}).width(), 5);
}

TEST(NoiseLevel, BadInputsAreErrors) {
  const ImageF image = test::constant(8, 8, 1, 0.5f);
  for (const int patch : {1, 4, -3}) {
    const Error e = error_of([&] { noise_level(image, {NoiseMethod::svd, patch}); });
    EXPECT_EQ(e.file(), "--patch");
    EXPECT_EQ(e.element(), std::to_string(patch));
  }
  EXPECT_THAT(error_of([] { noise_level(ImageF(), {}); }).reason(), HasSubstr("no pixels"));
  ImageF broken = image;
  broken.at(3, 2, 0) = NAN;
  EXPECT_EQ(error_of([&] { noise_level(broken, {}); }).element(), "pixel (3, 2), channel 0");
}

// 100 levels: 80 at 0.15², 12 at 0.5², 5 at 0.8², 3 at 1.1²; with 11 bins over [0, 1.1] the
// peak bin is [0.1, 0.2), centre 0.15; the nearest-rank 0.95 quantile is the 95th value, 0.64.
ImageF remap_example() {
  ImageF noise(10, 10, 1);
  std::vector<float>& n = noise.values();
  std::fill(n.begin(), n.begin() + 80, 0.0225f);
  std::fill(n.begin() + 80, n.begin() + 92, 0.25f);
  std::fill(n.begin() + 92, n.begin() + 97, 0.64f);
  std::fill(n.begin() + 97, n.end(), 1.21f);
  return noise;
}

TEST(Guidance, RemapsBetweenFourTimesThePeakAndTheQuantile) {
  const Guidance guidance = guidance_from_noise(remap_example(), {11, 0.95});
  EXPECT_NEAR(guidance.n_peak, 0.0225, 1e-6);
  EXPECT_NEAR(guidance.lower, 0.09, 1e-6);
  EXPECT_NEAR(guidance.upper, 0.64, 1e-6);
  const std::vector<float>& m = guidance.map.values();
  EXPECT_EQ(m[0], 1.f);                                // below lower: clamped to 1
  EXPECT_NEAR(m[80], 1 - (0.25 - 0.09) / 0.55, 1e-6);  // eq. (13)
  EXPECT_EQ(m[92], 0.f);                               // at upper
  EXPECT_EQ(m[99], 0.f);                               // above upper: clamped to 0
  EXPECT_NEAR(guidance_from_noise(remap_example(), {11, 0.9}).upper, 0.25, 1e-6);
}

TEST(Guidance, ConstantNoiseGivesAllOnes) {
  for (const float level : {0.f, 0.3f}) {
    const Guidance guidance = guidance_from_noise(test::constant(7, 5, 1, level));
    EXPECT_LE(guidance.upper, guidance.lower);
    for (const float m : guidance.map.values()) ASSERT_EQ(m, 1.f);
  }
  // A constant image has no noise at all.
  const ImageF noise = noise_level(test::constant(9, 9, 3, 0.4f), {});
  EXPECT_EQ(largest(noise), 0.f);
  const Guidance guidance = guidance_from_noise(noise);
  for (const float m : guidance.map.values()) ASSERT_EQ(m, 1.f);
}

TEST(Guidance, BadInputsAreErrors) {
  EXPECT_EQ(error_of([] { guidance_from_noise(remap_example(), {0, 0.95}); }).file(), "--bins");
  for (const double q : {0.0, 1.5}) {
    EXPECT_EQ(error_of([&] {
                guidance_from_noise(remap_example(), {256, q});
              }).file(),
              "--upper-quantile");
  }
  EXPECT_THAT(error_of([] { guidance_from_noise(test::constant(4, 4, 3, 0.1f)); }).reason(),
              HasSubstr("one channel"));
  EXPECT_THAT(error_of([] { guidance_from_noise(test::constant(4, 4, 1, -0.1f)); }).reason(),
              HasSubstr(">= 0"));
  EXPECT_THAT(error_of([] { guidance_from_noise(ImageF()); }).reason(), HasSubstr("no pixels"));
}

}  // namespace
}  // namespace glint::denoise
