#include "denoise/denoiser.h"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <chrono>

#include "core/error.h"
#include "core/resources.h"
#include "denoise/denoise_plugin.h"

namespace glint::denoise {

const std::vector<std::string>& denoise_method_names() {
  static const std::vector<std::string> names{"nlm", "dip", "guided-dip", "s2s", "guided-s2s"};
  return names;
}

bool method_is_guided(const std::string& method) {
  return method != "nlm" && is_guided(parse_neural_method(method));
}

NeuralParams DenoiserSettings::neural_params(NeuralMethod method) const {
  NeuralParams p = neural_preset(method, config);
  p.device = device;
  p.seed = seed;
  // The global thread limit (TBB's) also bounds libtorch's intra-op threads.
  p.threads = static_cast<int>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (iterations) p.iterations = *iterations;
  if (predictions) p.predictions = *predictions;
  if (levels) p.net.levels = *levels;
  if (channels) p.net.channels = *channels;
  if (learning_rate) p.learning_rate = *learning_rate;
  if (discard && is_guided(method)) p.masks.discard = *discard;
  if (dropout) p.dropout = *dropout;
  if (input_noise) p.input_perturbation = *input_noise;
  if (average) p.weighted_averaging = *average == "weighted";
  if (kappa_w) p.decay.warmup = *kappa_w;
  if (kappa_r) p.decay.rate = *kappa_r;
  if (kappa_c) p.decay.floor = *kappa_c;
  if (kappa_m) p.masks.exponent = *kappa_m;
  return p;
}

NoiseLevelParams DenoiserSettings::noise_params() const {
  return {parse_noise_method(noise_method), patch};
}

ImageF estimate_guidance(const ImageF& noisy, const DenoiserSettings& settings) {
  return guidance_from_noise(noise_level(noisy, settings.noise_params())).map;
}

void check_guidance(const ImageF& guidance, const ImageF& noisy, const std::string& name) {
  if (!guidance.same_size(noisy))
    throw Error(name, "",
                fmt::format("guidance map is {}x{} but the image is {}x{}", guidance.width(),
                            guidance.height(), noisy.width(), noisy.height()));
  if (guidance.channels() != 1) throw Error(name, "", "guidance map must have one channel");
}

DenoiseRun run_denoiser(const std::string& method, const DenoiserSettings& settings,
                        const ImageF& noisy, const ImageF* guidance,
                        const std::function<void(int, const ImageF&)>& snapshot,
                        int snapshot_every) {
  DenoiseRun run;
  if (method == "nlm") {
    const auto start = std::chrono::steady_clock::now();
    NlmParams nlm = settings.nlm;
    nlm.h_color = nlm.h;
    run.result = nlm_denoise(noisy, nlm);
    run.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.stats.device = "cpu";
    return run;
  }
  NeuralParams params = settings.neural_params(parse_neural_method(method));
  params.snapshot = snapshot;
  params.snapshot_every = snapshot_every;
  const auto entry =
      reinterpret_cast<DenoisePluginEntry>(plugin_entry(kDenoisePlugin, kDenoisePluginEntry));
  DenoisePluginCall call;
  call.noisy = &noisy;
  call.guidance = guidance;
  call.params = &params;
  call.result = &run.result;
  call.stats = &run.stats;
  if (entry(&call) != 0) call.failure.rethrow();
  return run;
}

}  // namespace glint::denoise
