#pragma once
// Helpers shared by the image-space denoise tests: synthetic images and error capture.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "core/error.h"
#include "core/image.h"
#include "support/error_of.h"

namespace glint::denoise::test {

// An image whose every value is `value`.
inline ImageF constant(int width, int height, int channels, float value) {
  return ImageF(width, height, channels, value);
}

// Values uniform in [low, high), deterministic for a seed.
inline ImageF random_image(int width, int height, int channels, std::uint64_t seed, float low = 0.f,
                           float high = 1.f) {
  ImageF image(width, height, channels);
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<float> uniform(low, high);
  for (float& v : image.values()) v = uniform(random);
  return image;
}

// A one-channel mask: 1 inside [x0, x1) × [y0, y1), 0 elsewhere.
inline ImageF box_mask(int width, int height, int x0, int y0, int x1, int y1) {
  ImageF mask(width, height, 1);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) mask.at(x, y, 0) = 1;
  }
  return mask;
}

using glint::test::error_of;

}  // namespace glint::denoise::test
