#pragma once
// A denoising method chosen by name, as `glint denoise run|eval` and the Python module offer it:
// OpenCV NLM in-process, the neural methods (DIP, Self2Self, guided or not) through the
// libtorch plugin (denoise_plugin.h), with the settings every front end shares.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/image.h"
#include "denoise/neural.h"
#include "denoise/nlm.h"
#include "denoise/noise_level.h"

namespace glint::denoise {

// All method names, NLM first: nlm, dip, guided-dip, s2s, guided-s2s.
const std::vector<std::string>& denoise_method_names();
// Whether `method` needs a guidance map (guided-dip, guided-s2s). Throws glint::Error for an
// unknown name.
bool method_is_guided(const std::string& method);

// The CLI's denoiser options: a preset (`config`) and optional overrides of its values.
struct DenoiserSettings {
  std::string config = "fast";  // full = the paper's settings, fast = CPU-practical
  std::string device = "auto";  // auto (CUDA when available), cpu or cuda
  std::uint64_t seed = 1;
  std::optional<int> iterations, predictions, levels, channels;
  std::optional<double> learning_rate, discard, dropout, input_noise;
  std::optional<std::string> average;  // guided DIP: "uniform" or "weighted"
  std::optional<int> kappa_w;
  std::optional<double> kappa_r, kappa_c, kappa_m;
  NlmParams nlm;
  // Guidance computed from the input when none is given.
  std::string noise_method = "svd";
  int patch = 7;

  // The preset of `method` with the overrides applied; libtorch's threads follow TBB's limit.
  NeuralParams neural_params(NeuralMethod method) const;
  NoiseLevelParams noise_params() const;
};

// The guidance map of `noisy` when none is given: its noise level (settings.noise_params())
// remapped by eq. (13).
ImageF estimate_guidance(const ImageF& noisy, const DenoiserSettings& settings);
// Throws glint::Error(name, "", reason) unless `guidance` is one channel of `noisy`'s size.
void check_guidance(const ImageF& guidance, const ImageF& noisy, const std::string& name);

struct DenoiseRun {
  ImageF result;
  NeuralStats stats;  // iterations 0 for NLM
};

// Runs `method` on `noisy`. `guidance` is needed by the guided methods only (nullptr
// otherwise). `snapshot` (may be empty) sees the estimate every `snapshot_every` iterations.
// Throws glint::Error for an unknown method, a missing plugin or a failed run.
DenoiseRun run_denoiser(const std::string& method, const DenoiserSettings& settings,
                        const ImageF& noisy, const ImageF* guidance,
                        const std::function<void(int, const ImageF&)>& snapshot = {},
                        int snapshot_every = 0);

}  // namespace glint::denoise
