// glint denoise noise-map: the per-pixel noise level of an image and the guidance map made from
// it (the guided-denoising paper, §3.1).
#include <fmt/format.h>

#include "cli_support.h"
#include "commands.h"
#include "core/log.h"
#include "core/timer.h"
#include "denoise/noise_level.h"
#include "io/image_io.h"
#include "io/json_report.h"

namespace glint::app {
namespace {

struct NoiseMapOptions {
  std::string input;
  std::string output;
  std::string raw;
  std::string report;
  std::string method = "svd";
  int patch = 7;
  denoise::GuidanceParams guidance;
};

void run_noise_map(const NoiseMapOptions& options) {
  StageTimings timings;
  ImageF image;
  {
    ScopedStage stage(timings, "read");
    image = io::read_image(options.input);
  }
  const denoise::NoiseLevelParams params{denoise::parse_noise_method(options.method),
                                         options.patch};
  ImageF noise;
  {
    ScopedStage stage(timings, "noise_level");
    noise = denoise::noise_level(image, params);
  }
  denoise::Guidance guidance;
  {
    ScopedStage stage(timings, "remap");
    guidance = denoise::guidance_from_noise(noise, options.guidance);
  }
  io::write_image(options.output, guidance.map, io::PngDepth::sixteen);
  if (!options.raw.empty()) io::write_image(options.raw, noise);
  log().info("{}: {}x{}x{}, {} noise level, patch {}: n_peak {:.3g}, bounds [{:.3g}, {:.3g}] -> {}",
             options.input, image.width(), image.height(), image.channels(), options.method,
             options.patch, guidance.n_peak, guidance.lower, guidance.upper, options.output);
  if (!options.report.empty())
    io::write_json(options.report, {{"command", command_line()},
                                    {"input", options.input},
                                    {"size", {image.width(), image.height(), image.channels()}},
                                    {"method", options.method},
                                    {"patch", options.patch},
                                    {"n_peak", guidance.n_peak},
                                    {"lower", guidance.lower},
                                    {"upper", guidance.upper},
                                    {"timings_ms", timings.to_json()}});
}

}  // namespace

void register_denoise_noise_map(CLI::App& denoise) {
  auto options = std::make_shared<NoiseMapOptions>();
  CLI::App* command = denoise.add_subcommand(
      "noise-map",
      "Estimate the per-pixel noise level and write the guidance map m in [0,1]\n"
      "(1 = clean, keep; 0 = noisy). The SVD estimate (default) splits each patch at its mean\n"
      "and measures the spread of each half about a fitted plane, so edges and smooth\n"
      "gradients do not look noisy; 'var' is the plain patch variance. Colour: per-channel\n"
      "maximum. The levels are remapped robustly: at or below 4x the histogram peak -> 1, at\n"
      "or above the 95th percentile -> 0.");
  command->add_option("input", options->input, "Image (PNG 8/16-bit, EXR, ...)")->required();
  command->add_option("-o,--output", options->output, "Guidance map (16-bit PNG or EXR)")
      ->required()
      ->check(kOutputFile);
  command->add_option("--method", options->method, "svd or var")
      ->check(CLI::IsMember({"svd", "var", "variance"}))
      ->capture_default_str();
  command->add_option("--patch", options->patch, "Patch side length (odd, >= 3)")
      ->capture_default_str();
  command->add_option("--bins", options->guidance.bins, "Histogram bins for the remapping")
      ->check(CLI::Range(8, 65536))
      ->capture_default_str();
  command
      ->add_option("--upper-quantile", options->guidance.upper_quantile,
                   "Noise-level quantile that maps to 0")
      ->check(CLI::Range(0.5, 1.0))
      ->capture_default_str();
  command->add_option("--raw", options->raw, "Also write the raw noise level (EXR recommended)");
  command->add_option("--report", options->report, "JSON report")->check(kOutputFile);
  command->footer(
      "Example:\n"
      "  glint denoise noise-map photo.png -o guidance.png --raw noise.exr\n"
      "  glint denoise noise-map albedo.exr -o guidance.png --method var --patch 9");
  command->callback([options] { run_noise_map(*options); });
}

}  // namespace glint::app
