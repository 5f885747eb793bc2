#include "denoise/torch_support.h"

#include <cstring>

#include "core/error.h"

namespace glint::denoise {

torch::Device resolve_device(const std::string& name) {
  if (name == "cpu") return torch::kCPU;
  if (name == "cuda" || name == "auto") {
    if (torch::cuda::is_available()) return torch::kCUDA;
    if (name == "auto") return torch::kCPU;
    throw Error("--device", name, "CUDA is not available (no GPU, or libtorch without CUDA)");
  }
  throw Error("--device", name, "unknown device (auto, cpu, cuda)");
}

torch::Tensor to_tensor(const ImageF& image, const torch::Device& device) {
  auto cpu = torch::empty({1, image.channels(), image.height(), image.width()}, torch::kFloat32);
  std::memcpy(cpu.data_ptr<float>(), image.values().data(), image.values().size() * sizeof(float));
  return cpu.to(device);
}

ImageF to_image(const torch::Tensor& tensor) {
  const torch::Tensor first = tensor[0].detach().to(torch::kCPU, torch::kFloat32).contiguous();
  ImageF image(static_cast<int>(first.size(2)), static_cast<int>(first.size(1)),
               static_cast<int>(first.size(0)));
  std::memcpy(image.values().data(), first.data_ptr<float>(),
              image.values().size() * sizeof(float));
  return image;
}

torch::Tensor pad_to_multiple(const torch::Tensor& x, int multiple) {
  const int64_t pad_h = (multiple - x.size(2) % multiple) % multiple;
  const int64_t pad_w = (multiple - x.size(3) % multiple) % multiple;
  if (pad_h == 0 && pad_w == 0) return x;
  namespace F = torch::nn::functional;
  return F::pad(x, F::PadFuncOptions({0, pad_w, 0, pad_h}).mode(torch::kReplicate));
}

torch::Tensor crop_to(const torch::Tensor& x, int64_t height, int64_t width) {
  return x.narrow(2, 0, height).narrow(3, 0, width);
}

}  // namespace glint::denoise
