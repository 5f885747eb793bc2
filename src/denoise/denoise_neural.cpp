// denoise_neural(): checks the inputs, sets up libtorch (seed, device, threads) and runs DIP or
// Self2Self.
#include <algorithm>
#include <chrono>
#include <string>
#include <thread>

#include "core/error.h"
#include "denoise/neural_impl.h"
#include "denoise/torch_support.h"

namespace glint::denoise {

void maybe_snapshot(const NeuralParams& params, int iteration,
                    const std::function<torch::Tensor()>& estimate) {
  if (params.snapshot && params.snapshot_every > 0 && iteration % params.snapshot_every == 0)
    params.snapshot(iteration, to_image(estimate().clamp(0.0, 1.0)));
}

ImageF denoise_neural(const ImageF& noisy, const ImageF* guidance, const NeuralParams& params,
                      NeuralStats* stats) {
  if (noisy.empty()) throw Error("input image", "", "has no pixels");
  if (is_guided(params.method)) {
    if (!guidance) throw Error(method_name(params.method), "", "needs a guidance map");
    if (!guidance->same_size(noisy) || guidance->channels() != 1)
      throw Error("guidance map", "",
                  "must be one channel of the input's size (" + std::to_string(noisy.width()) +
                      "x" + std::to_string(noisy.height()) + ")");
  }
  if (params.iterations < 1 || params.net.levels < 1 || params.net.channels < 1)
    throw Error(method_name(params.method), "", "needs iterations, levels and channels >= 1");
  // The U-Net halves the image `levels` times; its deepest level needs 2x2 pixels (reflection
  // padding and batch norm fail on a single row, column or value per channel).
  const int min_side = (1 << std::min(params.net.levels, 16)) + 1;
  if (noisy.width() < min_side || noisy.height() < min_side)
    throw Error("input image", "",
                "is " + std::to_string(noisy.width()) + "x" + std::to_string(noisy.height()) +
                    ": a " + std::to_string(params.net.levels) + "-level U-Net needs at least " +
                    std::to_string(min_side) + " pixels per side (use fewer --levels)");

  const auto start = std::chrono::steady_clock::now();
  torch::manual_seed(params.seed);
  // libtorch's CPU default can be a single intra-op thread; use every core unless told.
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  torch::set_num_threads(params.threads > 0 ? params.threads : static_cast<int>(cores));
  const torch::Device device = resolve_device(params.device);
  const torch::Tensor input = to_tensor(noisy, device);
  const ImageF* guide = is_guided(params.method) ? guidance : nullptr;

  NeuralStats local;
  local.device = device.str();
  ImageF result = is_self2self(params.method) ? run_self2self(input, guide, params, local)
                                              : run_dip(input, guide, params, local);
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = local;
  return result;
}

}  // namespace glint::denoise
