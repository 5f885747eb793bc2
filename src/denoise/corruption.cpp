#include "denoise/corruption.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "core/error.h"

namespace glint::denoise {
namespace {

// Sets the pixels whose centres lie in the ellipse; returns how many were not set before.
std::size_t fill_ellipse(ImageF& mask, double cx, double cy, double major, double minor,
                         double angle) {
  const double cos_a = std::cos(angle), sin_a = std::sin(angle);
  const int x0 = std::max(0, static_cast<int>(std::floor(cx - major)));
  const int x1 = std::min(mask.width() - 1, static_cast<int>(std::ceil(cx + major)));
  const int y0 = std::max(0, static_cast<int>(std::floor(cy - major)));
  const int y1 = std::min(mask.height() - 1, static_cast<int>(std::ceil(cy + major)));
  std::size_t added = 0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      const double along = (cos_a * dx + sin_a * dy) / major;
      const double across = (-sin_a * dx + cos_a * dy) / minor;
      if (along * along + across * across > 1 || mask.at(x, y, 0) == 1) continue;
      mask.at(x, y, 0) = 1;
      ++added;
    }
  }
  return added;
}

}  // namespace

ImageF blob_mask(int width, int height, double coverage, std::uint64_t seed) {
  if (width < 1 || height < 1) {
    throw Error("blob mask", std::to_string(width) + "x" + std::to_string(height),
                "needs at least one pixel");
  }
  if (!(coverage >= 0 && coverage <= 0.9)) {
    throw Error("--coverage", std::to_string(coverage), "must be in [0, 0.9]");
  }
  ImageF mask(width, height, 1);
  const double target = std::ceil(coverage * static_cast<double>(mask.pixel_count()));
  const double largest = target / 3;  // a few blobs, not one
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double covered = 0;
  while (covered < target) {
    // Never more than is missing, and at least a disc of radius 1.
    const double area = std::max(std::numbers::pi,
                                 std::min(largest * (0.5 + 0.5 * unit(random)), target - covered));
    const double aspect = 0.5 + 0.5 * unit(random);  // minor / major axis
    const double major = std::sqrt(area / (std::numbers::pi * aspect));
    const double angle = std::numbers::pi * unit(random);
    const double cx = width * unit(random), cy = height * unit(random);
    covered += static_cast<double>(fill_ellipse(mask, cx, cy, major, major * aspect, angle));
  }
  return mask;
}

ImageF add_noise_in_mask(const ImageF& clean, const ImageF& mask, double sigma, std::uint64_t seed,
                         bool clip) {
  if (!mask.same_size(clean) || mask.channels() != 1) {
    throw Error("noise mask", "", "must have one channel and the clean image's size");
  }
  if (!(sigma >= 0) || std::isinf(sigma)) {
    throw Error("--sigma", std::to_string(sigma), "must be finite and >= 0");
  }
  ImageF noisy = clean;
  std::mt19937_64 random(seed);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  for (int c = 0; c < noisy.channels(); ++c) {
    float* plane = noisy.plane(c);
    for (std::size_t i = 0; i < noisy.pixel_count(); ++i) {
      if (!(mask.values()[i] > 0.5f)) continue;
      const double value = plane[i] + sigma * gaussian(random);
      plane[i] = static_cast<float>(clip ? std::clamp(value, 0.0, 1.0) : value);
    }
  }
  return noisy;
}

}  // namespace glint::denoise
