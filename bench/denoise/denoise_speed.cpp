// Speed of the denoising stages: noise-level maps on a 1-megapixel colour image (the issue's
// "well under a second on 2 cores"), the remapping, the NLM baseline, and the per-iteration
// cost of each neural denoiser in the fast and full configurations at 256×256.
// Writes JSON (stdout, or --json FILE).
//
//   denoise_speed [--size 1024] [--net-size 256] [--full-iterations 3] [--json F]
#include <algorithm>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "core/progress.h"
#include "core/timer.h"
#include "denoise/corruption.h"
#include "denoise/neural.h"
#include "denoise/nlm.h"
#include "denoise/noise_level.h"
#include "denoise/test_patterns.h"
#include "io/json_report.h"
#include "support/machine.h"

namespace {

using namespace glint;

template <class F>
double median_seconds(int repeats, F&& f) {
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    Stopwatch watch;
    f();
    times.push_back(watch.elapsed_ms() / 1000.0);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

ImageF noisy_test_image(int size) {
  const ImageF clean = denoise::step_gradient_pattern(size, size, 3, 11);
  return denoise::add_noise_in_mask(clean, denoise::blob_mask(size, size, 0.3, 11), 50 / 255.0, 11);
}

// Seconds per optimisation step (and per prediction for S2S) of one method and configuration.
nlohmann::json neural_speed(denoise::NeuralMethod method, const std::string& config,
                            const ImageF& noisy, const ImageF& guidance, int iterations) {
  denoise::NeuralParams params = denoise::neural_preset(method, config);
  params.iterations = iterations;
  params.predictions = 0;
  denoise::NeuralStats training;
  denoise::denoise_neural(noisy, &guidance, params, &training);
  nlohmann::json entry{{"method", denoise::method_name(method)},
                       {"config", config},
                       {"levels", params.net.levels},
                       {"channels", params.net.channels},
                       {"parameters", training.parameters},
                       {"device", training.device},
                       {"seconds_per_iteration", training.seconds / iterations},
                       {"preset_iterations", denoise::neural_preset(method, config).iterations}};
  if (denoise::is_self2self(method)) {
    params.iterations = 1;
    params.predictions = iterations;
    denoise::NeuralStats predicting;
    denoise::denoise_neural(noisy, &guidance, params, &predicting);
    entry["seconds_per_prediction"] =
        (predicting.seconds - training.seconds / iterations) / iterations;
    entry["preset_predictions"] = denoise::neural_preset(method, config).predictions;
  }
  const double predictions_cost =
      entry.value("seconds_per_prediction", 0.0) * entry.value("preset_predictions", 0);
  entry["estimated_seconds_per_image"] =
      entry["seconds_per_iteration"].get<double>() * entry["preset_iterations"].get<int>() +
      predictions_cost;
  return entry;
}

}  // namespace

int main(int argc, char** argv) {
  int size = 1024, net_size = 256, full_iterations = 3, fast_iterations = 20;
  std::string json_path;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--size")
      size = std::stoi(argv[i + 1]);
    else if (flag == "--net-size")
      net_size = std::stoi(argv[i + 1]);
    else if (flag == "--full-iterations")
      full_iterations = std::stoi(argv[i + 1]);
    else if (flag == "--json")
      json_path = argv[i + 1];
    else {
      std::cerr
          << "usage: denoise_speed [--size N] [--net-size N] [--full-iterations N] [--json F]\n";
      return 2;
    }
  }
  set_quiet(true);
  nlohmann::json result{{"threads", std::thread::hardware_concurrency()}};

  const ImageF big = noisy_test_image(size);
  for (const auto method : {denoise::NoiseMethod::variance, denoise::NoiseMethod::svd}) {
    const denoise::NoiseLevelParams params{method, 7};
    ImageF level;
    const double seconds = median_seconds(5, [&] { level = denoise::noise_level(big, params); });
    const double remap = median_seconds(5, [&] { denoise::guidance_from_noise(level); });
    result["noise_level"].push_back(
        {{"method", method == denoise::NoiseMethod::svd ? "svd" : "var"},
         {"width", size},
         {"height", size},
         {"channels", 3},
         {"patch", 7},
         {"seconds", seconds},
         {"remap_seconds", remap},
         {"megapixels_per_second", size * size / seconds / 1e6}});
  }

  const ImageF small = noisy_test_image(net_size);
  result["nlm"] = {{"size", net_size},
                   {"seconds", median_seconds(3, [&] { denoise::nlm_denoise(small); })}};
  const ImageF guidance =
      denoise::guidance_from_noise(denoise::noise_level(small, {denoise::NoiseMethod::svd, 7})).map;
  for (const auto method : {denoise::NeuralMethod::dip, denoise::NeuralMethod::guided_dip,
                            denoise::NeuralMethod::s2s, denoise::NeuralMethod::guided_s2s}) {
    result["neural"].push_back(neural_speed(method, "fast", small, guidance, fast_iterations));
    result["neural"].push_back(neural_speed(method, "full", small, guidance, full_iterations));
  }
  result["peak_rss_mib"] = bench::peak_rss_mib();
  if (json_path.empty())
    std::cout << result.dump(2) << "\n";
  else
    io::write_json(json_path, result);
  return 0;
}
