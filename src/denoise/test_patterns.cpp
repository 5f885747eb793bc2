#include "denoise/test_patterns.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace glint::denoise {
namespace {

// Value = base + gx·x + gy·y per channel (x, y in [0,1]); gx = gy = 0 is a flat fill.
struct Fill {
  std::vector<float> base, gx, gy;
};

Fill random_fill(std::mt19937_64& random, int channels, bool gradient) {
  std::uniform_real_distribution<float> level(0.15f, 0.85f), slope(-0.4f, 0.4f);
  Fill fill;
  for (int c = 0; c < channels; ++c) {
    fill.base.push_back(level(random));
    fill.gx.push_back(gradient ? slope(random) : 0.f);
    fill.gy.push_back(gradient ? slope(random) : 0.f);
  }
  return fill;
}

}  // namespace

ImageF step_gradient_pattern(int width, int height, int channels, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  ImageF image(width, height, channels);
  const auto paint = [&](const Fill& fill, auto&& inside) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const float u = static_cast<float>(x) / width, v = static_cast<float>(y) / height;
        if (!inside(u, v)) continue;
        for (int c = 0; c < channels; ++c)
          image.at(x, y, c) = std::clamp(
              fill.base[c] + fill.gx[c] * (u - 0.5f) + fill.gy[c] * (v - 0.5f), 0.f, 1.f);
      }
  };
  paint(random_fill(random, channels, true), [](float, float) { return true; });
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  const int shapes = 6 + static_cast<int>(random() % 5);
  for (int s = 0; s < shapes; ++s) {
    const Fill fill = random_fill(random, channels, unit(random) < 0.5f);
    const float cx = unit(random), cy = unit(random), size = 0.08f + 0.25f * unit(random);
    switch (random() % 3) {
      case 0:  // rectangle
        paint(fill, [&](float u, float v) {
          return std::abs(u - cx) < size && std::abs(v - cy) < 0.6f * size;
        });
        break;
      case 1:  // disc
        paint(fill, [&](float u, float v) { return std::hypot(u - cx, v - cy) < size; });
        break;
      default: {  // a slanted stripe
        const float angle = 3.14159265f * unit(random), nx = std::cos(angle), ny = std::sin(angle);
        paint(fill, [&](float u, float v) {
          return std::abs((u - cx) * nx + (v - cy) * ny) < 0.3f * size;
        });
      }
    }
  }
  return image;
}

}  // namespace glint::denoise
