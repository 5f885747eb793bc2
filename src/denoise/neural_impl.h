#pragma once
// The two optimisation loops behind denoise_neural() (neural.h). `noisy` is (1, C, H, W) on the
// chosen device; `guidance` is the checked one-channel map, or null for the unguided methods.
#include <torch/torch.h>

#include <functional>

#include "denoise/neural.h"

namespace glint::denoise {

ImageF run_dip(const torch::Tensor& noisy, const ImageF* guidance, const NeuralParams& params,
               NeuralStats& stats);
ImageF run_self2self(const torch::Tensor& noisy, const ImageF* guidance, const NeuralParams& params,
                     NeuralStats& stats);

// Input and target masks (1, 1, H, W) of one Self2Self sample: one uniform number per pixel
// against the cumulative thresholds of eqs (20)-(23) (both < input-only < target-only).
struct SampledMasks {
  torch::Tensor input, target;
};
SampledMasks sample_masks(const torch::Tensor& both_below, const torch::Tensor& input_below,
                          const torch::Tensor& target_below);

// Hands the current estimate to params.snapshot every params.snapshot_every iterations
// (1-based), computing it only then.
void maybe_snapshot(const NeuralParams& params, int iteration,
                    const std::function<torch::Tensor()>& estimate);

}  // namespace glint::denoise
