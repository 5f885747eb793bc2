#pragma once
// libtorch plumbing shared by the neural denoisers: device choice, Image <-> tensor, padding to
// the U-Net's size multiple.
#include <torch/torch.h>

#include <string>

#include "core/image.h"

namespace glint::denoise {

// "auto" picks CUDA when the linked libtorch has it and a GPU is present; "cuda" without one
// -> glint::Error.
torch::Device resolve_device(const std::string& name);

// (1, C, H, W) float tensor on `device` holding a copy of the image.
torch::Tensor to_tensor(const ImageF& image, const torch::Device& device);
// The first batch element of a (N, C, H, W) tensor, copied back to the CPU.
ImageF to_image(const torch::Tensor& tensor);

// Replicate-pads H and W up to the next multiples of `multiple` (bottom and right).
torch::Tensor pad_to_multiple(const torch::Tensor& x, int multiple);
// The top-left height×width window of a padded tensor.
torch::Tensor crop_to(const torch::Tensor& x, int64_t height, int64_t width);

}  // namespace glint::denoise
