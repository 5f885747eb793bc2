// glint lights: near-field point lights (position, intensity) from a low-exposure light-capture
// RGB-D sequence (paper 1 §3.2), written as lights.json for the reflectance pipeline.
#include <fmt/format.h>

#include <filesystem>
#include <limits>
#include <memory>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/json_report.h"
#include "io/rgbd_sequence.h"
#include "reflectance/light_estimation.h"
#include "render/scene_json.h"

namespace glint::app {
namespace {

struct LightsOptions {
  std::string capture;
  std::string output;
  std::string report;
  float exposure = 0;  // 0: scene.json's camera.exposure, else 1
  bool flat_emitters = false;
  reflectance::LightEstimationParams params;
};

// The capture folder's ground-truth lights (scene.json), or none with a warning saying why.
std::vector<render::PointLight> ground_truth_lights(const std::string& folder) {
  const std::string path = (std::filesystem::path(folder) / "scene.json").string();
  if (!std::filesystem::exists(path)) return {};
  try {
    return render::read_scene_json(path).lights;
  } catch (const Error& e) {
    log().warn("no ground-truth comparison: {}", e.what());
    return {};
  }
}

// Per estimated light, the nearest ground-truth light: position error and intensity ratio.
nlohmann::json compare_with_ground_truth(const reflectance::LightEstimate& estimate,
                                         const std::vector<render::PointLight>& truth) {
  nlohmann::json comparisons = nlohmann::json::array();
  for (std::size_t l = 0; l < estimate.lights.size(); ++l) {
    const render::PointLight& light = estimate.lights[l];
    std::size_t nearest = 0;
    double error = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < truth.size(); ++t) {
      const double distance = (truth[t].position - light.position).norm();
      if (distance < error) {
        error = distance;
        nearest = t;
      }
    }
    const Eigen::Vector3f ratio = light.intensity.cwiseQuotient(truth[nearest].intensity);
    log().info(
        "  light {} vs ground truth {}: position error {:.1f} cm, intensity ratio "
        "({:.3f}, {:.3f}, {:.3f})",
        l, nearest, 100 * error, ratio.x(), ratio.y(), ratio.z());
    comparisons.push_back(
        {{"light", l},
         {"ground_truth", nearest},
         {"ground_truth_position", io::vector_json(truth[nearest].position)},
         {"ground_truth_intensity", io::vector_json(truth[nearest].intensity.cast<double>())},
         {"position_error_m", error},
         {"intensity_ratio", io::vector_json(ratio.cast<double>())}});
  }
  if (estimate.lights.size() != truth.size())
    log().warn("found {} lights, the ground truth has {}", estimate.lights.size(), truth.size());
  return comparisons;
}

void run_lights(const LightsOptions& options) {
  const Stopwatch watch;
  reflectance::LightEstimationParams params = options.params;
  if (options.exposure > 0) params.exposure = options.exposure;
  params.spherical_emitters = !options.flat_emitters;
  const io::RgbdSequence capture = io::open_rgbd_sequence(options.capture);

  ProgressBar progress("lights", capture.frames.size());
  const reflectance::LightEstimate estimate =
      reflectance::estimate_lights(capture, params, [&] { progress.advance(); });
  progress.finish();
  reflectance::write_lights_json(options.output, estimate);

  log().info("{}: {} frames at exposure {}{} -> {} lights in {}", options.capture,
             capture.frames.size(), estimate.exposure, options.exposure > 0 ? " (--exposure)" : "",
             estimate.lights.size(), options.output);
  nlohmann::json lights = nlohmann::json::array();
  for (std::size_t l = 0; l < estimate.lights.size(); ++l) {
    const render::PointLight& light = estimate.lights[l];
    const reflectance::LightSupport& support = estimate.support[l];
    log().info(
        "  light {}: position ({:.3f}, {:.3f}, {:.3f}) m, intensity ({:.3f}, {:.3f}, "
        "{:.3f}), radius {:.1f} cm, {} frames, {:.0f} px, spread {:.1f} cm",
        l, light.position.x(), light.position.y(), light.position.z(), light.intensity.x(),
        light.intensity.y(), light.intensity.z(), 100 * light.proxy_radius_m, support.frames,
        support.pixels, 100 * support.position_spread_m);
    lights.push_back({{"position", io::vector_json(light.position)},
                      {"intensity", io::vector_json(light.intensity.cast<double>())},
                      {"radius_m", light.proxy_radius_m},
                      {"frames", support.frames},
                      {"pixels", support.pixels},
                      {"position_spread_m", support.position_spread_m},
                      {"clipped_fraction", support.clipped_fraction}});
  }
  const std::vector<render::PointLight> truth = ground_truth_lights(options.capture);
  const nlohmann::json comparisons =
      truth.empty() ? nlohmann::json(nullptr) : compare_with_ground_truth(estimate, truth);

  if (options.report.empty()) return;
  io::write_json(options.report, {{"command", command_line()},
                                  {"capture", options.capture},
                                  {"format", capture.format},
                                  {"frames", capture.frames.size()},
                                  {"output", options.output},
                                  {"parameters",
                                   {{"exposure", estimate.exposure},
                                    {"min_luminance", params.min_luminance},
                                    {"bandwidth_m", params.clustering.bandwidth_m},
                                    {"min_cluster_px", params.min_cluster_px},
                                    {"merge_radius_m", params.fusion.merge_radius_m},
                                    {"min_frames", params.fusion.min_frames},
                                    {"spherical_emitters", params.spherical_emitters}}},
                                  {"lights", lights},
                                  {"ground_truth", comparisons},
                                  {"total_s", watch.elapsed_s()}});
}

}  // namespace

void register_lights_command(CLI::App& app) {
  auto options = std::make_shared<LightsOptions>();
  reflectance::LightEstimationParams& params = options->params;
  CLI::App* command = app.add_subcommand(
      "lights",
      "Estimate the scene's near-field point lights from a low-exposure light-capture RGB-D\n"
      "sequence with camera poses (reflectance paper §3.2): bright pixels are back-projected,\n"
      "clustered per frame by mean shift and fused over the sequence; each light's intensity is\n"
      "measured from its pixels' radiance and solid angle (src/reflectance/light_estimation.h).\n"
      "Intensities are in radiance units (pixel / exposure): divide the main sequence's pixels\n"
      "by its own exposure to compare.");
  command->add_option("capture", options->capture, "Light-capture sequence folder (with poses)")
      ->required();
  command->add_option("-o,--output", options->output, "lights.json to write")
      ->required()
      ->check(kOutputFile);
  command
      ->add_option("--exposure", options->exposure,
                   "Capture exposure (pixel = exposure * radiance); default: scene.json's "
                   "camera.exposure in the folder, else 1")
      ->check(kPositive);
  command
      ->add_option("--min-luminance", params.min_luminance,
                   "Linear luminance a light pixel reaches, in [0, 1] before the exposure")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--bandwidth", params.clustering.bandwidth_m, "Mean-shift radius, metres")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--merge-radius", params.fusion.merge_radius_m,
                   "Per-frame candidates this close (metres) fuse into one light")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--min-frames", params.fusion.min_frames, "Frames a light must be seen in")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--min-pixels", params.min_cluster_px, "Pixels a per-frame light needs")
      ->check(kPositive)
      ->capture_default_str();
  command->add_flag(
      "--flat-emitters", options->flat_emitters,
      "Lamps are flat (panels): no correction from the seen cap to a sphere's centre");
  command
      ->add_option("--report", options->report,
                   "JSON report: parameters, lights, ground-truth errors when scene.json has "
                   "lights")
      ->check(kOutputFile);
  command->footer(
      "Prints each light and, when the capture folder's scene.json holds ground-truth lights,\n"
      "the position error and intensity ratio per light.\n"
      "Examples:\n"
      "  glint synth lights --scene bunnies -o cap && glint lights cap -o lights.json\n"
      "  glint lights my_capture -o lights.json --exposure 0.002 --min-luminance 0.1");
  command->callback([options] { run_lights(*options); });
}

}  // namespace glint::app
