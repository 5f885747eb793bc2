#include "denoise/nlm.h"

#include <gtest/gtest.h>

#include <cmath>

#include "denoise/corruption.h"
#include "denoise/metrics.h"
#include "image_test_support.h"

namespace glint::denoise {
namespace {

using test::error_of;

// A smooth 64×64 pattern, the channels slightly out of phase (mostly luminance, like photos).
ImageF pattern(int channels) {
  ImageF image(64, 64, channels);
  for (int c = 0; c < channels; ++c) {
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        image.at(x, y, c) = 0.5f + 0.3f * std::sin(0.2f * x + 0.2f * c) * std::cos(0.15f * y);
      }
    }
  }
  return image;
}

TEST(Nlm, ReducesTheErrorOfANoisyPattern) {
  for (const int channels : {1, 2, 3}) {
    SCOPED_TRACE(channels);
    const ImageF clean = pattern(channels);
    const ImageF noisy = add_noise_in_mask(clean, test::constant(64, 64, 1, 1.f), 0.1, 1);
    const ImageF denoised = nlm_denoise(noisy);
    ASSERT_EQ(denoised.channels(), channels);
    ASSERT_TRUE(denoised.same_size(clean));
    for (const float v : denoised.values()) ASSERT_TRUE(v >= 0.f && v <= 1.f);
    EXPECT_GT(psnr(clean, denoised), psnr(clean, noisy) + 3) << psnr(clean, noisy);
  }
}

TEST(Nlm, KeepsColourChannelsInPlace) {
  ImageF red(16, 16, 3);
  std::fill_n(red.plane(0), red.pixel_count(), 1.f);
  const ImageF denoised = nlm_denoise(red);
  EXPECT_NEAR(denoised.at(8, 8, 0), 1.f, 2 / 255.f);
  EXPECT_NEAR(denoised.at(8, 8, 2), 0.f, 2 / 255.f);
}

TEST(Nlm, BadParametersAndImagesAreErrors) {
  const ImageF image = pattern(1);
  EXPECT_EQ(error_of([&] { nlm_denoise(image, {0.f, 25.f, 7, 21}); }).file(), "--h");
  EXPECT_EQ(error_of([&] { nlm_denoise(image, {25.f, 25.f, 6, 21}); }).file(), "--template-window");
  EXPECT_EQ(error_of([&] { nlm_denoise(image, {25.f, 25.f, 7, 0}); }).file(), "--search-window");
  EXPECT_EQ(error_of([] { nlm_denoise(ImageF()); }).file(), "noisy image");
  ImageF broken = image;
  broken.at(1, 1, 0) = NAN;
  EXPECT_EQ(error_of([&] { nlm_denoise(broken); }).file(), "noisy image");
}

}  // namespace
}  // namespace glint::denoise
