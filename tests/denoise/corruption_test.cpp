#include "denoise/corruption.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "image_test_support.h"

namespace glint::denoise {
namespace {

using test::error_of;

double covered_fraction(const ImageF& mask) {
  const auto& v = mask.values();
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

TEST(BlobMask, CoversTheTargetWithinFivePercent) {
  for (const auto& [width, height] : {std::pair{64, 64}, {128, 96}, {256, 256}}) {
    for (const double coverage : {0.1, 0.3, 0.5}) {
      for (std::uint64_t seed = 0; seed < 5; ++seed) {
        const ImageF mask = blob_mask(width, height, coverage, seed);
        ASSERT_EQ(mask.width(), width);
        ASSERT_EQ(mask.height(), height);
        ASSERT_EQ(mask.channels(), 1);
        for (const float m : mask.values()) ASSERT_TRUE(m == 0.f || m == 1.f);
        EXPECT_NEAR(covered_fraction(mask), coverage, 0.05 * coverage)
            << width << "x" << height << " seed " << seed;
      }
    }
  }
}

TEST(BlobMask, IsDeterministicPerSeed) {
  EXPECT_EQ(blob_mask(80, 60, 0.3, 42).values(), blob_mask(80, 60, 0.3, 42).values());
  EXPECT_NE(blob_mask(80, 60, 0.3, 42).values(), blob_mask(80, 60, 0.3, 43).values());
}

TEST(BlobMask, ZeroCoverageIsEmptyAndBadArgumentsAreErrors) {
  EXPECT_EQ(covered_fraction(blob_mask(10, 10, 0.0, 1)), 0.0);
  EXPECT_EQ(error_of([] { blob_mask(10, 10, 0.95, 1); }).file(), "--coverage");
  EXPECT_EQ(error_of([] { blob_mask(10, 10, -0.1, 1); }).file(), "--coverage");
  EXPECT_EQ(error_of([] { blob_mask(0, 10, 0.3, 1); }).element(), "0x10");
}

TEST(AddNoiseInMask, ChangesOnlyMaskedPixelsWithTheRequestedSigma) {
  const ImageF clean = test::constant(128, 128, 3, 0.5f);
  const ImageF mask = test::box_mask(128, 128, 0, 0, 64, 128);
  const ImageF noisy = add_noise_in_mask(clean, mask, 0.1, 3, false);
  double sum = 0, squares = 0;
  std::size_t count = 0;
  for (int c = 0; c < 3; ++c) {
    for (int y = 0; y < 128; ++y) {
      for (int x = 0; x < 128; ++x) {
        const double d = noisy.at(x, y, c) - clean.at(x, y, c);
        if (x >= 64) {
          ASSERT_EQ(d, 0.0);
          continue;
        }
        sum += d, squares += d * d, ++count;
      }
    }
  }
  const double mean = sum / static_cast<double>(count);
  EXPECT_NEAR(mean, 0.0, 0.005);
  EXPECT_NEAR(std::sqrt(squares / static_cast<double>(count) - mean * mean), 0.1, 0.005);
}

TEST(AddNoiseInMask, ClipsDeterministicallyAndChecksItsInputs) {
  const ImageF clean = test::random_image(32, 32, 2, 1);
  const ImageF mask = test::constant(32, 32, 1, 1.f);
  const ImageF noisy = add_noise_in_mask(clean, mask, 0.5, 9);
  for (const float v : noisy.values()) ASSERT_TRUE(v >= 0.f && v <= 1.f);
  EXPECT_EQ(noisy.values(), add_noise_in_mask(clean, mask, 0.5, 9).values());
  EXPECT_NE(noisy.values(), add_noise_in_mask(clean, mask, 0.5, 10).values());
  EXPECT_EQ(add_noise_in_mask(clean, mask, 0.0, 9).values(), clean.values());
  EXPECT_EQ(
      error_of([&] { add_noise_in_mask(clean, test::constant(32, 31, 1, 1.f), 0.1, 1); }).file(),
      "noise mask");
  EXPECT_EQ(error_of([&] { add_noise_in_mask(clean, mask, -0.1, 1); }).file(), "--sigma");
}

}  // namespace
}  // namespace glint::denoise
