// Self2Self, plain and guided (the guided-denoising paper, §3.3): the U-Net learns to predict
// pixels it did not see from those it saw, with decoder dropout; the result averages many
// dropout samples.
#include <random>

#include "core/progress.h"
#include "denoise/neural_impl.h"
#include "denoise/torch_support.h"
#include "denoise/unet.h"

namespace glint::denoise {
namespace {

// Per-pixel maps computed once from the importance p_imp (eq. (19)).
struct MaskModel {
  torch::Tensor both_below, input_below, target_below;  // cumulative thresholds of eqs (20)-(22)
  std::vector<torch::Tensor> drop_rates;                // eq. (24) per decoder level
};

MaskModel make_mask_model(const ImageF* guidance, int64_t height, int64_t width,
                          const NeuralParams& params, const torch::Device& device) {
  const int w = static_cast<int>(width), h = static_cast<int>(height);
  ImageF both(w, h, 1), input(w, h, 1), target(w, h, 1), rate(w, h, 1);
  for (std::size_t i = 0; i < both.pixel_count(); ++i) {
    const double importance =
        guidance ? importance_probability(guidance->values()[i], params.masks.exponent) : 0.0;
    const MaskProbabilities q = mask_probabilities(importance, params.masks);
    both.values()[i] = static_cast<float>(q.both);
    input.values()[i] = static_cast<float>(q.both + q.input_only);
    target.values()[i] = static_cast<float>(q.both + q.input_only + q.target_only);
    rate.values()[i] = static_cast<float>(modulated_dropout(importance, params.dropout));
  }
  MaskModel model;
  model.both_below = to_tensor(both, device);
  model.input_below = to_tensor(input, device);
  model.target_below = to_tensor(target, device);
  // Decoder level l runs at 1/2^l resolution: average the padded full-resolution rates.
  const torch::Tensor full = pad_to_multiple(to_tensor(rate, device), 1 << params.net.levels);
  for (int l = 0; l < params.net.levels; ++l)
    model.drop_rates.push_back(l == 0 ? full : torch::avg_pool2d(full, 1 << l));
  return model;
}

}  // namespace

SampledMasks sample_masks(const torch::Tensor& both_below, const torch::Tensor& input_below,
                          const torch::Tensor& target_below) {
  const torch::Tensor u = torch::rand_like(both_below);
  SampledMasks masks;
  masks.input = (u < input_below).to(torch::kFloat32);
  masks.target = ((u < both_below) | ((u >= input_below) & (u < target_below))).to(torch::kFloat32);
  return masks;
}

ImageF run_self2self(const torch::Tensor& noisy, const ImageF* guidance, const NeuralParams& params,
                     NeuralStats& stats) {
  const auto height = noisy.size(2), width = noisy.size(3), channels = noisy.size(1);
  const int multiple = 1 << params.net.levels;
  const MaskModel model = make_mask_model(guidance, height, width, params, noisy.device());
  UNet net(static_cast<int>(channels), static_cast<int>(channels), params.net);
  net->to(noisy.device());
  stats.parameters = parameter_count(*net);
  torch::optim::Adam optimiser(net->parameters(), torch::optim::AdamOptions(params.learning_rate));
  std::mt19937_64 flip_random(params.seed);

  // One masked, randomly flipped pass; returns the prediction and the target mask.
  const auto sample = [&]() {
    const SampledMasks masks =
        sample_masks(model.both_below, model.input_below, model.target_below);
    std::vector<int64_t> flip_dims;
    if (params.flips) {
      if (flip_random() & 1) flip_dims.push_back(3);
      if (flip_random() & 1) flip_dims.push_back(2);
    }
    const auto flip = [&](const torch::Tensor& t) {
      return flip_dims.empty() ? t : torch::flip(t, flip_dims);
    };
    std::vector<torch::Tensor> rates;
    for (const torch::Tensor& r : model.drop_rates) rates.push_back(flip(r));
    const torch::Tensor input = flip(pad_to_multiple(noisy * masks.input, multiple));
    torch::Tensor output = crop_to(flip(net->forward(input, rates)), height, width);
    return std::make_pair(output, masks.target);
  };

  ProgressBar progress(method_name(params.method),
                       static_cast<std::size_t>(params.iterations + params.predictions));
  for (int i = 0; i < params.iterations; ++i) {
    optimiser.zero_grad();
    const auto [output, target] = sample();
    // Squared error on the pixels the network did not see (and guided: the important ones).
    const torch::Tensor loss = ((output - noisy) * target).pow(2).sum() /
                               (target.sum() * static_cast<double>(channels)).clamp_min(1.0);
    loss.backward();
    optimiser.step();
    maybe_snapshot(params, i + 1, [&] { return output.detach(); });
    progress.advance();
  }

  torch::NoGradGuard no_grad;
  torch::Tensor sum = torch::zeros_like(noisy);
  for (int k = 0; k < params.predictions; ++k) {
    sum += sample().first;
    progress.advance();
  }
  progress.finish();
  stats.iterations = params.iterations;
  stats.predictions = params.predictions;
  return to_image((sum / std::max(1, params.predictions)).clamp(0.0, 1.0));
}

}  // namespace glint::denoise
