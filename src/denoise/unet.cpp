#include "denoise/unet.h"

#include <string>

namespace glint::denoise {
namespace {

namespace nn = torch::nn;

constexpr double kLeakySlope = 0.2;

nn::Sequential conv_norm_act(int in, int out, int kernel, int stride) {
  nn::Sequential block;
  if (kernel > 1) block->push_back(nn::ReflectionPad2d(kernel / 2));
  block->push_back(nn::Conv2d(nn::Conv2dOptions(in, out, kernel).stride(stride)));
  block->push_back(nn::BatchNorm2d(out));
  block->push_back(nn::LeakyReLU(nn::LeakyReLUOptions().negative_slope(kLeakySlope)));
  return block;
}

}  // namespace

torch::Tensor pixel_dropout(const torch::Tensor& x, const torch::Tensor& rate) {
  if (!rate.defined()) return x;
  const torch::Tensor keep = (1.0 - rate).clamp_min(1e-3).expand_as(x);
  return x * torch::bernoulli(keep) / keep;
}

UpBlockImpl::UpBlockImpl(int in_channels, int out_channels) {
  norm_in = register_module("norm_in", nn::BatchNorm2d(in_channels));
  pad = register_module("pad", nn::ReflectionPad2d(1));
  conv3 = register_module("conv3", nn::Conv2d(nn::Conv2dOptions(in_channels, out_channels, 3)));
  norm3 = register_module("norm3", nn::BatchNorm2d(out_channels));
  conv1 = register_module("conv1", nn::Conv2d(nn::Conv2dOptions(out_channels, out_channels, 1)));
  norm1 = register_module("norm1", nn::BatchNorm2d(out_channels));
}

torch::Tensor UpBlockImpl::forward(torch::Tensor x, const torch::Tensor& drop_rate) {
  const auto act = [](const torch::Tensor& t) { return torch::leaky_relu(t, kLeakySlope); };
  x = norm_in(x);
  x = act(norm3(conv3(pad(pixel_dropout(x, drop_rate)))));
  return act(norm1(conv1(pixel_dropout(x, drop_rate))));
}

UNetImpl::UNetImpl(int in_channels, int out_channels, const UNetConfig& config) {
  int level_in = in_channels;
  for (int l = 0; l < config.levels; ++l) {
    nn::Sequential down = conv_norm_act(level_in, config.channels, 3, 2);
    down->extend(*conv_norm_act(config.channels, config.channels, 3, 1));
    down_.push_back(register_module("down" + std::to_string(l), down));
    if (config.skip_channels > 0)
      skip_.push_back(register_module("skip" + std::to_string(l),
                                      conv_norm_act(level_in, config.skip_channels, 1, 1)));
    up_.push_back(
        register_module("up" + std::to_string(l),
                        UpBlock(config.skip_channels + config.channels, config.channels)));
    level_in = config.channels;
  }
  output_ =
      register_module("output", nn::Conv2d(nn::Conv2dOptions(config.channels, out_channels, 1)));
}

torch::Tensor UNetImpl::forward(const torch::Tensor& x,
                                const std::vector<torch::Tensor>& drop_rates) {
  std::vector<torch::Tensor> skips;
  torch::Tensor y = x;
  for (int l = 0; l < levels(); ++l) {
    if (!skip_.empty()) skips.push_back(skip_[l]->forward(y));
    y = down_[l]->forward(y);
  }
  for (int l = levels() - 1; l >= 0; --l) {
    const auto size = std::vector<int64_t>{y.size(2) * 2, y.size(3) * 2};
    y = torch::upsample_bilinear2d(y, size, /*align_corners=*/false);
    if (!skips.empty()) y = torch::cat({skips[l], y}, 1);
    y = up_[l]->forward(y, drop_rates.empty() ? torch::Tensor() : drop_rates[l]);
  }
  return torch::sigmoid(output_(y));
}

std::int64_t parameter_count(torch::nn::Module& module) {
  std::int64_t count = 0;
  for (const auto& p : module.parameters()) count += p.numel();
  return count;
}

}  // namespace glint::denoise
