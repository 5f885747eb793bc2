#include "denoise_support.h"

#include <tbb/global_control.h>

#include <chrono>

#include "cli_support.h"
#include "core/error.h"
#include "core/progress.h"
#include "denoise/denoise_plugin.h"

namespace glint::app {

const std::vector<std::string>& denoise_method_names() {
  static const std::vector<std::string> names{"nlm", "dip", "guided-dip", "s2s", "guided-s2s"};
  return names;
}

bool method_is_guided(const std::string& method) {
  return method != "nlm" && denoise::is_guided(denoise::parse_neural_method(method));
}

void DenoiserOptions::add_options(CLI::App& command) {
  command
      .add_option("--config", config,
                  "full = the paper's settings (5 levels x 128 filters; GPU-sized), fast = "
                  "CPU-practical (4 x 16; DIP 1,200 iterations, S2S 800)")
      ->check(CLI::IsMember({"full", "fast"}))
      ->capture_default_str();
  command.add_option("--device", device, "auto (CUDA when available), cpu or cuda")
      ->check(CLI::IsMember({"auto", "cpu", "cuda"}))
      ->capture_default_str();
  command.add_option("--seed", seed, "Seed of every random choice")->capture_default_str();
  command.add_option("--iterations", iterations, "Optimisation steps (overrides --config)")
      ->check(kPositive);
  command.add_option("--predictions", predictions, "S2S: dropout samples averaged at the end")
      ->check(kPositive);
  command.add_option("--levels", levels, "U-Net depth (overrides --config)")
      ->check(CLI::Range(1, 8));
  command.add_option("--channels", channels, "U-Net filters per level (overrides --config)")
      ->check(kPositive);
  command.add_option("--lr", learning_rate, "Adam learning rate (overrides --config)")
      ->check(kPositive);
  command
      .add_option("--input-noise", input_noise,
                  "DIP: sigma of the per-iteration input perturbation (full 1/30, fast 0)")
      ->check(kNonNegative);
  command
      .add_option("--average", average,
                  "Guided DIP: eq. (14)'s output average, 'uniform' (the paper's) or 'weighted' "
                  "(each pixel's rate scaled by its loss weight, so let-go pixels keep their "
                  "estimate; fast's default)")
      ->check(CLI::IsMember({"uniform", "weighted"}));
  command.add_option("--pd", discard, "Guided S2S: p_d of eqs (17)-(18) (full 0.01, fast 1)")
      ->check(CLI::Range(0.0, 1.0));
  command.add_option("--dropout", dropout, "S2S: decoder dropout rate (default 0.3)")
      ->check(CLI::Range(0.0, 0.95));
  command.add_option("--kappa-w", kappa_w, "Guided DIP: warm-up iterations of eq. (16) (225)")
      ->check(kNonNegative);
  command.add_option("--kappa-r", kappa_r, "Guided DIP: decay rate of eq. (16) (0.15)")
      ->check(kPositive);
  command.add_option("--kappa-c", kappa_c, "Guided DIP: weight floor of eq. (16) (0.02)")
      ->check(CLI::Range(0.0, 1.0));
  command.add_option("--kappa-m", kappa_m, "Guided S2S: importance exponent of eq. (19) (2)")
      ->check(kPositive);
  command.add_option("--nlm-h", nlm.h, "NLM: filter strength on the 0-255 scale (also hColor)")
      ->check(kPositive)
      ->capture_default_str();
  command
      .add_option("--noise-method", noise_method,
                  "Guidance from the input when --guidance is not given: svd or var")
      ->check(CLI::IsMember({"svd", "var", "variance"}))
      ->capture_default_str();
  command.add_option("--patch", patch, "Noise-level patch size (odd)")->capture_default_str();
}

denoise::NeuralParams DenoiserOptions::neural_params(denoise::NeuralMethod method) const {
  denoise::NeuralParams p = denoise::neural_preset(method, config);
  p.device = device;
  p.seed = seed;
  // The global --threads limit (TBB's) also bounds libtorch's intra-op threads.
  p.threads = static_cast<int>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (iterations) p.iterations = *iterations;
  if (predictions) p.predictions = *predictions;
  if (levels) p.net.levels = *levels;
  if (channels) p.net.channels = *channels;
  if (learning_rate) p.learning_rate = *learning_rate;
  if (discard && denoise::is_guided(method)) p.masks.discard = *discard;
  if (dropout) p.dropout = *dropout;
  if (input_noise) p.input_perturbation = *input_noise;
  if (average) p.weighted_averaging = *average == "weighted";
  if (kappa_w) p.decay.warmup = *kappa_w;
  if (kappa_r) p.decay.rate = *kappa_r;
  if (kappa_c) p.decay.floor = *kappa_c;
  if (kappa_m) p.masks.exponent = *kappa_m;
  return p;
}

denoise::NoiseLevelParams DenoiserOptions::noise_params() const {
  return {denoise::parse_noise_method(noise_method), patch};
}

DenoiseRun run_denoiser(const std::string& method, const DenoiserOptions& options,
                        const ImageF& noisy, const ImageF* guidance,
                        const std::function<void(int, const ImageF&)>& snapshot,
                        int snapshot_every) {
  DenoiseRun run;
  if (method == "nlm") {
    const auto start = std::chrono::steady_clock::now();
    denoise::NlmParams nlm = options.nlm;
    nlm.h_color = nlm.h;
    run.result = denoise::nlm_denoise(noisy, nlm);
    run.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.stats.device = "cpu";
    return run;
  }
  denoise::NeuralParams params = options.neural_params(denoise::parse_neural_method(method));
  params.snapshot = snapshot;
  params.snapshot_every = snapshot_every;
  const auto entry = reinterpret_cast<denoise::DenoisePluginEntry>(
      plugin_entry(denoise::kDenoisePlugin, denoise::kDenoisePluginEntry));
  denoise::DenoisePluginCall call;
  call.noisy = &noisy;
  call.guidance = guidance;
  call.params = &params;
  call.quiet = is_quiet();
  call.result = &run.result;
  call.stats = &run.stats;
  if (entry(&call) != 0) call.failure.rethrow();
  return run;
}

}  // namespace glint::app
