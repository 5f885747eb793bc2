#pragma once
// The encoder/decoder network both neural denoisers train (DIP's "skip" U-Net, see neural.h's
// UNetConfig). The decoder can apply per-pixel dropout before each convolution (Self2Self).
#include <torch/torch.h>

#include <vector>

#include "denoise/neural.h"

namespace glint::denoise {

// One decoder level: batch norm over [skip, upsampled], 3×3 conv, 1×1 conv.
struct UpBlockImpl : torch::nn::Module {
  UpBlockImpl(int in_channels, int out_channels);
  // `drop_rate` is a (1,1,h,w) map of per-pixel dropout rates, or undefined for none.
  torch::Tensor forward(torch::Tensor x, const torch::Tensor& drop_rate);

  torch::nn::BatchNorm2d norm_in{nullptr}, norm3{nullptr}, norm1{nullptr};
  torch::nn::ReflectionPad2d pad{nullptr};
  torch::nn::Conv2d conv3{nullptr}, conv1{nullptr};
};
TORCH_MODULE(UpBlock);

struct UNetImpl : torch::nn::Module {
  UNetImpl(int in_channels, int out_channels, const UNetConfig& config);
  // `drop_rates[l]` is the dropout-rate map for decoder level l (full resolution at l = 0);
  // pass an empty vector for no dropout. Height and width must be multiples of 2^levels.
  torch::Tensor forward(const torch::Tensor& x, const std::vector<torch::Tensor>& drop_rates);

  int levels() const { return static_cast<int>(down_.size()); }

 private:
  std::vector<torch::nn::Sequential> down_, skip_;
  std::vector<UpBlock> up_;
  torch::nn::Conv2d output_{nullptr};
};
TORCH_MODULE(UNet);

// Inverted dropout with a per-pixel rate map broadcast over channels (eq. (24) per neuron).
torch::Tensor pixel_dropout(const torch::Tensor& x, const torch::Tensor& rate);

std::int64_t parameter_count(torch::nn::Module& module);

}  // namespace glint::denoise
