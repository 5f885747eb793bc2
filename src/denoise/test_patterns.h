#pragma once
// Procedural clean images with the structures that fool a variance-based noise estimate: flat
// regions meeting at sharp steps, and smooth linear and radial gradients (the SVD estimate of
// the guided-denoising paper, §3.1.2, is built to ignore both).
#include <cstdint>

#include "core/image.h"

namespace glint::denoise {

// A `channels`-channel image of random overlapping rectangles, discs and stripes, each either
// flat or carrying a linear gradient, over a gradient background. Deterministic for a seed.
ImageF step_gradient_pattern(int width, int height, int channels, std::uint64_t seed);

}  // namespace glint::denoise
