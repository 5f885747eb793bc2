// glint denoise eval: the evaluation protocol of the guided-denoising issue. Each clean image
// (a centre crop) is corrupted with Gaussian noise inside random blobs (~30 % of the pixels,
// the rest left clean, as in the paper's Fig. 9); the noise maps are scored against the true
// mask (ROC-AUC) and every method is scored on the whole image, the clean part and the noisy
// part (PSNR, SSIM), with its runtime.
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "denoise/corruption.h"
#include "denoise/metrics.h"
#include "denoise/test_patterns.h"
#include "denoise_support.h"
#include "io/image_io.h"
#include "io/json_report.h"

namespace glint::app {
namespace {

namespace fs = std::filesystem;

struct EvalOptions {
  std::vector<std::string> images;
  std::string data;
  std::string set = "kodak";
  int count = 8;
  int crop = 256;
  std::vector<std::string> methods{"nlm", "dip", "guided-dip", "s2s", "guided-s2s"};
  double sigma = 50.0;
  double coverage = 0.3;
  std::uint64_t protocol_seed = 2022;
  bool oracle_guidance = false;
  int trace_every = 0;
  std::string save;
  std::string report;
  denoise::DenoiserSettings denoiser;
};

struct TestImage {
  std::string name;
  ImageF clean;
};

ImageF centre_crop(const ImageF& image, int size, const std::string& name) {
  if (size <= 0) return image;
  if (image.width() < size || image.height() < size)
    throw Error(name, "", fmt::format("is smaller than the {0}x{0} crop", size));
  const int x0 = (image.width() - size) / 2, y0 = (image.height() - size) / 2;
  ImageF crop(size, size, image.channels());
  for (int c = 0; c < image.channels(); ++c)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) crop.at(x, y, c) = image.at(x0 + x, y0 + y, c);
  return crop;
}

std::vector<TestImage> load_images(const EvalOptions& options) {
  std::vector<TestImage> images;
  if (options.set == "patterns" && options.images.empty()) {
    const int size = options.crop > 0 ? options.crop : 256;
    for (int i = 0; i < options.count; ++i)
      images.push_back({fmt::format("pattern-{:02d}", i),
                        denoise::step_gradient_pattern(size, size, 3, options.protocol_seed + i)});
    return images;
  }
  std::vector<std::string> files = options.images;
  if (files.empty()) {
    const fs::path folder = fs::path(options.data) / "images" / options.set;
    if (!fs::is_directory(folder))
      throw Error(folder.string(), "",
                  "no such image folder (set --data or GLINT_DATA, or pass --images)");
    for (const auto& entry : fs::directory_iterator(folder))
      if (entry.path().extension() == ".png") files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
    if (static_cast<int>(files.size()) > options.count) files.resize(options.count);
  }
  if (files.empty()) throw Error(options.data, "", "no images to evaluate");
  for (const std::string& file : files)
    images.push_back(
        {fs::path(file).stem().string(), centre_crop(io::read_image(file), options.crop, file)});
  return images;
}

// 1 − v: the clean part of a 0/1 noise mask, or a guidance map as noisiness (high = noisy,
// like the raw levels).
ImageF inverted(const ImageF& image) {
  ImageF inverse = image;
  for (float& v : inverse.values()) v = 1.f - v;
  return inverse;
}

// PSNR of the whole image, its clean part and its noisy part.
nlohmann::json psnr_parts(const ImageF& clean, const ImageF& result, const ImageF& noisy_mask,
                          const ImageF& clean_mask) {
  return {{"psnr", denoise::psnr(clean, result)},
          {"psnr_clean", denoise::psnr(clean, result, &clean_mask)},
          {"psnr_noisy", denoise::psnr(clean, result, &noisy_mask)}};
}

nlohmann::json quality(const ImageF& clean, const ImageF& result, const ImageF& noisy_mask,
                       const ImageF& clean_mask) {
  nlohmann::json values = psnr_parts(clean, result, noisy_mask, clean_mask);
  values["ssim"] = denoise::ssim(clean, result);
  values["ssim_clean"] = denoise::ssim(clean, result, &clean_mask);
  values["ssim_noisy"] = denoise::ssim(clean, result, &noisy_mask);
  return values;
}

// Mean, median, min and max of one metric over the images.
nlohmann::json spread(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  double sum = 0;
  for (double v : values) sum += v;
  const std::size_t n = values.size();
  const double median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return {{"mean", sum / n}, {"median", median}, {"min", values.front()}, {"max", values.back()}};
}

void save(const EvalOptions& options, const std::string& name, const std::string& what,
          const ImageF& image) {
  if (options.save.empty()) return;
  io::write_image((fs::path(options.save) / (name + "-" + what + ".png")).string(), image);
}

void run_eval(const EvalOptions& options) {
  for (const std::string& method : options.methods)
    if (method != "nlm") denoise::parse_neural_method(method);
  if (!options.save.empty()) fs::create_directories(options.save);
  const std::vector<TestImage> images = load_images(options);
  const denoise::NoiseLevelParams guidance_params = options.denoiser.noise_params();

  nlohmann::json per_image = nlohmann::json::array();
  std::map<std::string, std::map<std::string, std::vector<double>>> samples;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const TestImage& image = images[i];
    const ImageF& clean = image.clean;
    const ImageF mask = denoise::blob_mask(clean.width(), clean.height(), options.coverage,
                                           options.protocol_seed + i);
    const ImageF clean_mask = inverted(mask);
    const ImageF noisy = denoise::add_noise_in_mask(clean, mask, options.sigma / 255.0,
                                                    options.protocol_seed * 7919 + i);
    nlohmann::json entry{{"image", image.name},
                         {"size", {clean.width(), clean.height(), clean.channels()}}};
    const auto record = [&](const std::string& method, const nlohmann::json& values) {
      entry["methods"][method] = values;
      for (const auto& [key, value] : values.items())
        if (value.is_number()) samples[method][key].push_back(value.get<double>());
    };
    record("noisy input", quality(clean, noisy, mask, clean_mask));

    ImageF estimated_guidance;  // from --noise-method, for the guided methods
    for (const denoise::NoiseMethod method :
         {denoise::NoiseMethod::variance, denoise::NoiseMethod::svd}) {
      denoise::NoiseLevelParams params = guidance_params;
      params.method = method;
      const ImageF level = denoise::noise_level(noisy, params);
      const denoise::Guidance guidance = denoise::guidance_from_noise(level);
      const std::string name = method == denoise::NoiseMethod::svd ? "svd" : "var";
      record("noise map " + name,
             {{"auc", denoise::roc_auc(level, mask)},
              {"auc_guidance", denoise::roc_auc(inverted(guidance.map), mask)}});
      save(options, image.name, "guidance-" + name, guidance.map);
      if (method == guidance_params.method) estimated_guidance = guidance.map;
    }
    save(options, image.name, "clean", clean);
    save(options, image.name, "noisy", noisy);
    save(options, image.name, "mask", mask);

    for (const std::string& method : options.methods) {
      const ImageF& guidance = options.oracle_guidance ? clean_mask : estimated_guidance;
      // The quality of the running estimate over the iterations (DIP's Fig. 3-style curves).
      nlohmann::json trace = nlohmann::json::array();
      const auto score_estimate = [&](int iteration, const ImageF& estimate) {
        nlohmann::json point = psnr_parts(clean, estimate, mask, clean_mask);
        point["iteration"] = iteration;
        trace.push_back(std::move(point));
      };
      const denoise::DenoiseRun run = denoise::run_denoiser(
          method, options.denoiser, noisy, denoise::method_is_guided(method) ? &guidance : nullptr,
          score_estimate, options.trace_every);
      nlohmann::json values = quality(clean, run.result, mask, clean_mask);
      if (!trace.empty()) values["trace"] = trace;
      values["seconds"] = run.stats.seconds;
      values["iterations"] = run.stats.iterations;
      record(method, values);
      save(options, image.name, method, run.result);
      if (method == "nlm") {
        // Reference: NLM's result pasted only inside the true noisy mask.
        ImageF oracle = noisy;
        for (int c = 0; c < oracle.channels(); ++c)
          for (std::size_t p = 0; p < oracle.pixel_count(); ++p)
            if (mask.plane(0)[p] > 0.5f) oracle.plane(c)[p] = run.result.plane(c)[p];
        record("nlm in true mask", quality(clean, oracle, mask, clean_mask));
      }
      log().info(
          "{} [{}/{}] {:<12} PSNR {:6.2f} (clean {:6.2f}, noisy {:6.2f}) SSIM {:.4f}  {:6.1f} s",
          image.name, i + 1, images.size(), method, values["psnr"].get<double>(),
          values["psnr_clean"].get<double>(), values["psnr_noisy"].get<double>(),
          values["ssim"].get<double>(), run.stats.seconds);
    }
    per_image.push_back(entry);
  }

  nlohmann::json summary;
  for (const auto& [method, metrics] : samples)
    for (const auto& [metric, values] : metrics) summary[method][metric] = spread(values);
  fmt::print("{} images ({}), sigma {}/255 in {:.0f} % blobs, protocol seed {}, config {}\n",
             images.size(), options.set, options.sigma, options.coverage * 100,
             options.protocol_seed, options.denoiser.config);
  fmt::print("{:<18} {:>9} {:>9} {:>9} {:>8} {:>8} {:>9}\n", "method (mean)", "PSNR", "clean",
             "noisy", "SSIM", "AUC", "seconds");
  for (const auto& item : summary.items()) {
    const nlohmann::json& metrics = item.value();
    const auto mean = [&](const char* key) {
      return metrics.contains(key) ? fmt::format("{:.3f}", metrics[key]["mean"].get<double>())
                                   : std::string("-");
    };
    fmt::print("{:<18} {:>9} {:>9} {:>9} {:>8} {:>8} {:>9}\n", item.key(), mean("psnr"),
               mean("psnr_clean"), mean("psnr_noisy"), mean("ssim"), mean("auc"), mean("seconds"));
  }
  if (!options.report.empty())
    io::write_json(options.report,
                   {{"command", command_line()},
                    {"protocol",
                     {{"set", options.set},
                      {"crop", options.crop},
                      {"sigma_255", options.sigma},
                      {"coverage", options.coverage},
                      {"seed", options.protocol_seed},
                      {"clipped", true},
                      {"values", "float, as stored (no sRGB decoding)"}}},
                    {"config", options.denoiser.config},
                    {"guidance", options.oracle_guidance ? "oracle (true mask)"
                                                         : options.denoiser.noise_method},
                    {"denoiser_seed", options.denoiser.seed},
                    {"images", per_image},
                    {"summary", summary}});
}

}  // namespace

void register_denoise_eval(CLI::App& denoise) {
  auto options = std::make_shared<EvalOptions>();
  const char* data = std::getenv("GLINT_DATA");
  options->data = data ? data : "../shared/data";
  CLI::App* command = denoise.add_subcommand(
      "eval",
      "The evaluation protocol: centre crops of clean images, Gaussian noise (sigma/255) inside\n"
      "random blobs covering ~30 % of each image, the rest clean. Scores the variance and SVD\n"
      "noise maps against the true mask (ROC-AUC) and each method on the whole image, the clean\n"
      "part and the noisy part (PSNR, SSIM), with runtimes; mean/median/min/max over images.");
  command->add_option("--images", options->images, "Clean images (default: the --set folder)");
  command->add_option("--data", options->data, "Data folder ($GLINT_DATA)")->capture_default_str();
  command
      ->add_option("--set", options->set,
                   "Folder under <data>/images (kodak, skimage, ...) or 'patterns' (procedural "
                   "steps and gradients)")
      ->capture_default_str();
  command->add_option("--count", options->count, "Images: the first N of the set")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--crop", options->crop, "Centre crop side (0 = whole image)")
      ->check(kNonNegative)
      ->capture_default_str();
  command->add_option("--methods", options->methods, "Methods to run (none: noise maps only)")
      ->delimiter(',')
      ->capture_default_str();
  command->add_option("--sigma", options->sigma, "Noise sigma on the 0-255 scale")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--coverage", options->coverage, "Fraction of pixels made noisy")
      ->check(CLI::Range(0.01, 0.95))
      ->capture_default_str();
  command->add_option("--protocol-seed", options->protocol_seed, "Seed of the blobs and noise")
      ->capture_default_str();
  command->add_flag("--oracle-guidance", options->oracle_guidance,
                    "Guide with the true clean mask instead of the estimated map (an upper bound "
                    "that separates the method from the noise-map quality)");
  command
      ->add_option("--trace-every", options->trace_every,
                   "Neural methods: score the running estimate every N iterations into the "
                   "report (PSNR whole/clean/noisy over the iterations; 0 = off)")
      ->check(kNonNegative)
      ->capture_default_str();
  command->add_option("--save", options->save, "Folder for clean/noisy/mask/guidance/results");
  command->add_option("--report", options->report, "JSON report (per image and summary)")
      ->check(kOutputFile);
  add_denoiser_options(*command, options->denoiser);
  command->footer(
      "Examples:\n"
      "  glint denoise eval --set kodak --count 8 --report denoise-kodak.json\n"
      "  glint denoise eval --set patterns --count 20 --methods none   # noise maps only\n"
      "  glint denoise eval --images a.png b.png --methods nlm,guided-s2s --save out/");
  command->callback([options] {
    if (options->methods.size() == 1 && options->methods[0] == "none") options->methods.clear();
    run_eval(*options);
  });
}

}  // namespace glint::app
