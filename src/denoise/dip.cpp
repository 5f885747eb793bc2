// Deep Image Prior, plain and guided (the guided-denoising paper, §3.2).
#include "core/progress.h"
#include "denoise/neural_impl.h"
#include "denoise/torch_support.h"
#include "denoise/unet.h"

namespace glint::denoise {

ImageF run_dip(const torch::Tensor& noisy, const ImageF* guidance, const NeuralParams& params,
               NeuralStats& stats) {
  const auto height = noisy.size(2), width = noisy.size(3);
  const int multiple = 1 << params.net.levels;
  UNet net(params.input_channels, static_cast<int>(noisy.size(1)), params.net);
  net->to(noisy.device());
  stats.parameters = parameter_count(*net);
  torch::optim::Adam optimiser(net->parameters(), torch::optim::AdamOptions(params.learning_rate));

  // The fixed network input: `input_channels` planes of U[0, input_scale], padded size.
  const torch::Tensor input =
      pad_to_multiple(torch::zeros({1, params.input_channels, height, width}, noisy.options()),
                      multiple)
          .uniform_(0.0, params.input_scale);
  const torch::Tensor importance =
      guidance ? to_tensor(*guidance, noisy.device()) : torch::Tensor();

  torch::Tensor average;
  ProgressBar progress(method_name(params.method), static_cast<std::size_t>(params.iterations));
  for (int i = 0; i < params.iterations; ++i) {
    optimiser.zero_grad();
    const torch::Tensor perturbed = input + torch::randn_like(input) * params.input_perturbation;
    const torch::Tensor output = crop_to(net->forward(perturbed, {}), height, width);
    torch::Tensor residual = output - noisy;
    // eq. (15): mean of (residual·w)², w of eq. (16) (1 during the warm-up).
    torch::Tensor weight;
    if (importance.defined() && i >= params.decay.warmup) {
      weight = decayed_weight(i, importance, params.decay);
      residual = residual * weight;
    }
    residual.pow(2).mean().backward();
    optimiser.step();
    // eq. (14): exponential average of the outputs; with weighted averaging a pixel's rate is
    // also scaled by its w, so a pixel let go keeps the estimate it had then.
    const torch::Tensor current = output.detach();
    if (!average.defined()) {
      average = current;
    } else {
      torch::Tensor step = (current - average) * (1.0 - params.averaging);
      if (params.weighted_averaging && weight.defined()) step = step * weight;
      average = average + step;
    }
    maybe_snapshot(params, i + 1, [&] { return average; });
    progress.advance();
  }
  progress.finish();
  stats.iterations = params.iterations;
  return to_image(average.clamp(0.0, 1.0));
}

}  // namespace glint::denoise
