#pragma once
// What `glint denoise run` and `glint denoise eval` share: the denoiser options and running a
// method by name (NLM in-process, the neural ones through the libtorch plugin).
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/image.h"
#include "denoise/neural.h"
#include "denoise/nlm.h"
#include "denoise/noise_level.h"

namespace glint::app {

// All method names, NLM first.
const std::vector<std::string>& denoise_method_names();

struct DenoiserOptions {
  std::string config = "fast";
  std::string device = "auto";
  std::uint64_t seed = 1;
  std::optional<int> iterations, predictions, levels, channels;
  std::optional<double> learning_rate, discard, dropout, input_noise;
  std::optional<std::string> average;
  std::optional<int> kappa_w;
  std::optional<double> kappa_r, kappa_c, kappa_m;
  denoise::NlmParams nlm;
  // Guidance computed from the input when none is given.
  std::string noise_method = "svd";
  int patch = 7;

  void add_options(CLI::App& command);
  denoise::NeuralParams neural_params(denoise::NeuralMethod method) const;
  denoise::NoiseLevelParams noise_params() const;
};

struct DenoiseRun {
  ImageF result;
  denoise::NeuralStats stats;  // iterations 0 for NLM
};

// Runs `method` ("nlm" or a neural method). `guidance` is needed by the guided methods only.
DenoiseRun run_denoiser(const std::string& method, const DenoiserOptions& options,
                        const ImageF& noisy, const ImageF* guidance,
                        const std::function<void(int, const ImageF&)>& snapshot = {},
                        int snapshot_every = 0);

bool method_is_guided(const std::string& method);

}  // namespace glint::app
