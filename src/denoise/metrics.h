#pragma once
// Image quality metrics for the denoising evaluation, and ROC-AUC for judging a noise map.
// Masks are one-channel images of the same size; a pixel counts when its value is > 0.5.
#include "core/image.h"

namespace glint::denoise {

// PSNR in dB with peak value 1 over all channels (and only the masked pixels when `mask` is
// given). +infinity for identical images. Throws glint::Error for a size or channel mismatch,
// an empty image or a mask that selects no pixel.
double psnr(const ImageF& reference, const ImageF& test, const ImageF* mask = nullptr);

// SSIM (Wang et al. 2004): 11×11 Gaussian window with σ = 1.5, K1 = 0.01, K2 = 0.03, L = 1,
// evaluated at every pixel; at the borders the window is cut to the image and renormalised
// (no padding values enter the statistics). The SSIM map is averaged over the (masked)
// pixels per channel, then over the channels. Errors as for psnr.
double ssim(const ImageF& reference, const ImageF& test, const ImageF* mask = nullptr);

// Area under the ROC curve of `score` (one channel; higher = more likely positive) against
// `truth` (> 0.5 positive), i.e. the Mann-Whitney probability that a random positive scores
// above a random negative, ties counted half. Throws glint::Error for mismatched sizes,
// non-finite scores, or a truth mask without positives or without negatives.
double roc_auc(const ImageF& score, const ImageF& truth);

}  // namespace glint::denoise
