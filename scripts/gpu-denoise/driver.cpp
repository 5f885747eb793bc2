// The driver of scripts/gpu-denoise/run.sh (not part of glint's build): runs glint's neural
// denoisers (src/denoise, the code `glint denoise run` loads as its plugin) on raw planar
// float32 images, in one process for a list of jobs so that CUDA starts once. A job line:
//   METHOD CONFIG NOISY GUIDANCE|- WIDTH HEIGHT CHANNELS OUT ITERATIONS PREDICTIONS
// (ITERATIONS, PREDICTIONS 0: the configuration's). GD_DEVICE overrides the device (cuda).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"
#include "core/progress.h"
#include "denoise/neural.h"

using namespace glint;
using namespace glint::denoise;

static ImageF read_raw(const std::string& path, int w, int h, int c) {
  ImageF image(w, h, c);
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(image.values().data()),
          std::streamsize(image.values().size() * 4));
  if (!in) throw Error(path, "", "short raw image");
  return image;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: driver JOBS TIME_LIMIT_S\n");
    return 2;
  }
  set_quiet(true);
  const double limit = std::atof(argv[2]);
  const auto start = std::chrono::steady_clock::now();
  std::ifstream jobs(argv[1]);
  std::string line;
  while (std::getline(jobs, line)) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed > limit) {
      std::printf("SKIP (time limit) %s\n", line.c_str());
      continue;
    }
    std::istringstream fields(line);
    std::string method, config, noisy_path, guide_path, out_path;
    int w, h, c, iterations, predictions;
    if (!(fields >> method >> config >> noisy_path >> guide_path >> w >> h >> c >> out_path >>
          iterations >> predictions))
      continue;
    try {
      NeuralParams params = neural_preset(parse_neural_method(method), config);
      params.device = std::getenv("GD_DEVICE") ? std::getenv("GD_DEVICE") : "cuda";
      if (iterations > 0) params.iterations = iterations;
      if (predictions > 0) params.predictions = predictions;
      const ImageF noisy = read_raw(noisy_path, w, h, c);
      ImageF guidance;
      if (guide_path != "-") guidance = read_raw(guide_path, w, h, 1);
      NeuralStats stats;
      const ImageF result =
          denoise_neural(noisy, guide_path != "-" ? &guidance : nullptr, params, &stats);
      std::ofstream out(out_path, std::ios::binary);
      out.write(reinterpret_cast<const char*>(result.values().data()),
                std::streamsize(result.values().size() * 4));
      std::printf(
          "RESULT %s %s %s iterations %d predictions %d seconds %.2f device %s parameters %lld\n",
          method.c_str(), config.c_str(), out_path.c_str(), stats.iterations, stats.predictions,
          stats.seconds, stats.device.c_str(), static_cast<long long>(stats.parameters));
      std::fflush(stdout);
    } catch (const std::exception& e) {
      std::printf("FAILED %s: %s\n", line.c_str(), e.what());
      std::fflush(stdout);
    }
  }
  return 0;
}
