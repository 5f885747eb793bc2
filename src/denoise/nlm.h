#pragma once
// The non-local means baseline (Buades et al. 2005) through OpenCV's photo module.
#include "core/image.h"

namespace glint::denoise {

struct NlmParams {
  float h = 25.f;           // filter strength for luminance (grey: the only one), 0..255 scale
  float h_color = 25.f;     // filter strength for colour components (3 channels only)
  int template_window = 7;  // odd patch side
  int search_window = 21;   // odd search area side
};

// Denoises the image quantised to 8 bits (values clamped to [0,1]): three channels (R, G, B)
// with cv::fastNlMeansDenoisingColored, one with cv::fastNlMeansDenoising, any other count
// each channel alone as grey. Returns values in [0,1] (multiples of 1/255). Throws
// glint::Error for bad parameters, an empty image or NaN values.
ImageF nlm_denoise(const ImageF& noisy, const NlmParams& params = {});

}  // namespace glint::denoise
