#pragma once
// The evaluation protocol's corruption (paper 2, Fig. 9): Gaussian noise concentrated in a
// few regions of an otherwise clean image, with the regions known as ground truth.
#include <cstdint>

#include "core/image.h"

namespace glint::denoise {

// A binary mask (one channel, 0 or 1) of random hard-edged elliptic blobs: blobs are added
// until they cover at least `coverage` of the image (in [0, 0.9]); each blob covers at most
// what is still missing, so the result overshoots by a few pixels at most. The same seed gives
// the same mask (std::mt19937_64). Throws glint::Error for a bad size or coverage.
ImageF blob_mask(int width, int height, double coverage, std::uint64_t seed);

// `clean` plus N(0, sigma²) noise, drawn independently for every channel of every pixel where
// `mask` (one channel, same size) is > 0.5; clipped to [0, 1] when `clip`. The same seed gives
// the same noise. Throws glint::Error for a mismatched mask or a negative sigma.
ImageF add_noise_in_mask(const ImageF& clean, const ImageF& mask, double sigma, std::uint64_t seed,
                         bool clip = true);

}  // namespace glint::denoise
