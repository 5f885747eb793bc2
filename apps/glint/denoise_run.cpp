// glint denoise run: denoises one image with guided/plain DIP or Self2Self, or OpenCV NLM.
#include <fmt/format.h>

#include <filesystem>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "denoise_support.h"
#include "io/image_io.h"
#include "io/json_report.h"

namespace glint::app {
namespace {

struct RunOptions {
  std::string input;
  std::string output;
  std::string method = "guided-s2s";
  std::string guidance;
  std::string save_guidance;
  std::string snapshot_dir = "snapshots";
  int snapshot_every = 0;
  int depth = 8;
  std::string report;
  denoise::DenoiserSettings denoiser;
};

void run_denoise(const RunOptions& options) {
  const ImageF noisy = io::read_image(options.input);
  ImageF guidance;
  if (denoise::method_is_guided(options.method)) {
    if (!options.guidance.empty()) {
      guidance = io::read_image(options.guidance);
      denoise::check_guidance(guidance, noisy, options.guidance);
    } else {
      guidance = denoise::estimate_guidance(noisy, options.denoiser);
    }
    if (!options.save_guidance.empty())
      io::write_image(options.save_guidance, guidance, io::PngDepth::sixteen);
  }
  const io::PngDepth depth = options.depth == 16 ? io::PngDepth::sixteen : io::PngDepth::eight;
  std::function<void(int, const ImageF&)> snapshot;
  if (options.snapshot_every > 0) {
    std::filesystem::create_directories(options.snapshot_dir);
    const std::string extension = std::filesystem::path(options.output).extension().string();
    snapshot = [&options, extension, depth](int iteration, const ImageF& estimate) {
      io::write_image((std::filesystem::path(options.snapshot_dir) /
                       fmt::format("{}-{:06d}{}", options.method, iteration, extension))
                          .string(),
                      estimate, depth);
    };
  }
  const denoise::DenoiseRun run = denoise::run_denoiser(options.method, options.denoiser, noisy,
                                                        guidance.empty() ? nullptr : &guidance,
                                                        snapshot, options.snapshot_every);
  io::write_image(options.output, run.result, depth);
  log().info("{}: {} on {}, {} iterations, {:.1f} s -> {}", options.input, options.method,
             run.stats.device, run.stats.iterations, run.stats.seconds, options.output);
  if (!options.report.empty())
    io::write_json(options.report, {{"command", command_line()},
                                    {"input", options.input},
                                    {"output", options.output},
                                    {"method", options.method},
                                    {"config", options.denoiser.config},
                                    {"device", run.stats.device},
                                    {"iterations", run.stats.iterations},
                                    {"predictions", run.stats.predictions},
                                    {"parameters", run.stats.parameters},
                                    {"seconds", run.stats.seconds}});
}

}  // namespace

void register_denoise_run(CLI::App& denoise) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* command = denoise.add_subcommand(
      "run",
      "Denoise one image. Guided methods keep pixels the guidance map marks clean (m = 1) and\n"
      "denoise the rest: guided-dip down-weights each pixel's loss on a schedule set by m\n"
      "(eqs 15-16); guided-s2s lets the network see and fit important pixels and masks the\n"
      "others (eqs 17-24). Without --guidance the map is estimated from the input (SVD).\n"
      "Any channel count; values as stored in the file.");
  command->add_option("input", options->input, "Noisy image (PNG 8/16-bit, EXR, ...)")->required();
  command->add_option("-o,--output", options->output, "Denoised image (.png or .exr)")
      ->required()
      ->check(kOutputFile);
  command->add_option("--method", options->method, "guided-s2s, s2s, guided-dip, dip or nlm")
      ->check(CLI::IsMember(denoise::denoise_method_names()))
      ->capture_default_str();
  command->add_option("--guidance", options->guidance,
                      "Guidance map (one channel, the image's size; from 'noise-map')");
  command->add_option("--save-guidance", options->save_guidance,
                      "Write the guidance map used (estimated or given)");
  command
      ->add_option("--snapshot-every", options->snapshot_every,
                   "Write the current estimate every N iterations")
      ->check(kNonNegative);
  command->add_option("--snapshot-dir", options->snapshot_dir, "Folder for the snapshots")
      ->capture_default_str();
  command->add_option("--depth", options->depth, "PNG output bit depth (8 or 16)")
      ->check(CLI::IsMember({8, 16}))
      ->capture_default_str();
  command->add_option("--report", options->report, "JSON report")->check(kOutputFile);
  add_denoiser_options(*command, options->denoiser);
  command->footer(
      "Examples:\n"
      "  glint denoise run noisy.png -o clean.png                      # guided S2S, fast\n"
      "  glint denoise run noisy.png -o clean.png --method guided-dip --guidance m.png\n"
      "  glint denoise run albedo.exr -o albedo-dn.exr --config full --device cuda\n"
      "  glint denoise run noisy.png -o nlm.png --method nlm --nlm-h 25");
  command->callback([options] { run_denoise(*options); });
}

}  // namespace glint::app
