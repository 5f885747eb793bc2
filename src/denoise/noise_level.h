#pragma once
// Per-pixel noise level estimates and the guidance map derived from them (paper 2, §3.1).
#include <string>

#include "core/image.h"

namespace glint::denoise {

enum class NoiseMethod { svd, variance };

// "svd" | "var" | "variance"; anything else throws glint::Error("--method", name, reason).
NoiseMethod parse_noise_method(const std::string& name);

struct NoiseLevelParams {
  NoiseMethod method = NoiseMethod::svd;
  int patch = 7;  // side length of the square neighbourhood N(x, y): odd, at least 3
};

// Noise level n(x, y) of every pixel, one channel, in squared image units:
// - variance: the patch variance, eq. (5);
// - svd: the patch split at its mean into a lower and an upper subset, eq. (7)-(8), each lifted
//   to points (x', y', I) with x', y' in pixels, eq. (9); a subset's noise is the smallest
//   eigenvalue of its population covariance (= smallest singular value² / count of the
//   centred points, eq. (10)-(11)): the variance across the plane fitted to it. n_svd is the
//   smaller of the two, eq. (12). A subset of at most 3 pixels fits a plane exactly and says
//   nothing about noise, so it is left out of the minimum (a patch where both are that small,
//   possible only in images less than 3 pixels wide or high, gets 0). Pixels equal to the
//   mean go to the upper subset.
// Several channels: computed per channel, then the per-pixel maximum (§3.1).
// Borders: the patch is shifted to lie inside the image, so a pixel closer than patch/2 to the
// border shares the nearest full patch (an image smaller than the patch uses all its rows or
// columns). Throws glint::Error for a bad patch size, an empty image or a non-finite value.
ImageF noise_level(const ImageF& image, const NoiseLevelParams& params);

struct GuidanceParams {
  int bins = 256;                // histogram bins over sqrt(n), from 0 to its maximum
  double upper_quantile = 0.95;  // n at this quantile maps to 0, in (0, 1]
};

struct Guidance {
  ImageF map;         // m(x, y) in [0, 1]: 1 keeps the pixel, 0 marks it noisy (eq. (4))
  double n_peak = 0;  // squared centre of the fullest histogram bin of sqrt(n)
  double lower = 0;   // 4 n_peak: noise levels at or below it map to 1
  double upper = 0;   // the upper_quantile of n: levels at or above it map to 0
};

// Remapping, eq. (13): m = clamp(1 - (n - lower) / (upper - lower), 0, 1). The quantile is the
// nearest-rank one (the smallest n with at least that fraction of pixels at or below it). When
// upper <= lower (e.g. a constant image) nothing stands out as noisy and the map is all ones.
// Throws glint::Error unless `noise` is a non-empty, one-channel map of finite values >= 0.
Guidance guidance_from_noise(const ImageF& noise, const GuidanceParams& params = {});

}  // namespace glint::denoise
