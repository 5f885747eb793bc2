// glint render: a scene.json rendered along its trajectory into an RGB-D sequence with ground
// truth (docs/reflectance.md, "render").
#include <fmt/format.h>

#include <cmath>
#include <optional>

#include "cli_support.h"
#include "commands.h"
#include "core/limits.h"
#include "core/log.h"
#include "io/json_report.h"
#include "render/scene_json.h"
#include "render/sequence_writer.h"

namespace glint::app {
namespace {

struct RenderOptions {
  std::string scene_path;
  std::string output;
  std::string report;
  render::SequenceOptions sequence;
  std::optional<int> width, height;
  std::optional<float> exposure;
  bool no_shadows = false;
  std::optional<int> bounces, indirect_samples;
};

void run_render(const RenderOptions& options) {
  render::Scene scene = render::read_scene_json(options.scene_path);
  Intrinsics& intrinsics = scene.camera.intrinsics;
  if (options.width || options.height) {
    const double aspect = double(intrinsics.height) / intrinsics.width;
    const int width = options.width.value_or(int(std::lround(*options.height / aspect)));
    const int height = options.height.value_or(int(std::lround(*options.width * aspect)));
    intrinsics = intrinsics.resized(width, height);
    limits::check_intrinsics(intrinsics, "--width/--height", "");
  }
  if (options.exposure) scene.camera.exposure = *options.exposure;
  if (options.no_shadows) scene.shadows = false;
  if (options.bounces) scene.bounces = *options.bounces;
  if (options.indirect_samples) scene.indirect_samples = *options.indirect_samples;
  const render::SequenceStats stats =
      render::write_sequence(scene, options.output, options.sequence);
  log().info("{}: {} frames {}x{} -> {} in {:.1f} s (median {:.1f} ms render, {:.1f} ms per frame)",
             options.scene_path, stats.frames, intrinsics.width, intrinsics.height, options.output,
             stats.seconds, stats.median_render_ms, stats.median_frame_ms);
  if (!options.report.empty())
    io::write_json(options.report, {{"command", command_line()},
                                    {"scene", options.scene_path},
                                    {"output", options.output},
                                    {"size", {intrinsics.width, intrinsics.height}},
                                    {"first_frame", options.sequence.first_frame},
                                    {"frames", stats.frames},
                                    {"shadows", scene.shadows},
                                    {"bounces", scene.bounces},
                                    {"indirect_samples", scene.indirect_samples},
                                    {"objects", scene.objects.size()},
                                    {"lights", scene.lights.size()},
                                    {"environment", scene.environment.has_value()},
                                    {"seconds", stats.seconds},
                                    {"median_render_ms", stats.median_render_ms},
                                    {"median_frame_ms", stats.median_frame_ms}});
}

}  // namespace

void register_render_command(CLI::App& app) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* command = app.add_subcommand(
      "render",
      "Render a scene (scene.json: objects with Ward materials, point lights, optional HDR\n"
      "environment, camera and trajectory) into an RGB-D sequence: rgb/ (8-bit sRGB, exposed\n"
      "and clipped), depth/ (16-bit mm), associations.txt, groundtruth.txt (TUM),\n"
      "intrinsics.json, gt/ (depth, normal, segment, kd, ks, alpha) and scene.json.\n"
      "Direct light by default; --bounces N adds N bounces of path-traced indirect light\n"
      "(docs/reflectance.md, 'render').");
  command->add_option("scene", options->scene_path, "Scene description (scene.json)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("-o,--output", options->output, "Sequence folder (replaced if it holds one)")
      ->required();
  command
      ->add_option("--frames", options->sequence.frame_count,
                   "Frames to render (-1 = to the end of the trajectory)")
      ->capture_default_str();
  command->add_option("--first", options->sequence.first_frame, "First trajectory index")
      ->check(kNonNegative)
      ->capture_default_str();
  command->add_option("--width", options->width, "Image width (scales the intrinsics)")
      ->check(kPositive);
  command->add_option("--height", options->height, "Image height (scales the intrinsics)")
      ->check(kPositive);
  command->add_option("--exposure", options->exposure, "Override the camera exposure")
      ->check(kPositive);
  command->add_flag("--no-shadows", options->no_shadows, "Skip shadow rays");
  command
      ->add_option("--bounces", options->bounces,
                   "Indirect bounces to path trace (overrides scene.json's \"bounces\", default "
                   "0 = direct light only, the reflectance pipeline's image model)")
      ->check(CLI::Range(0, limits::kMaxBounces));
  command
      ->add_option("--indirect-samples", options->indirect_samples,
                   "Paths per pixel for the indirect light (overrides scene.json, default 32); "
                   "its noise falls as 1/sqrt(samples), time grows linearly")
      ->check(CLI::Range(1, limits::kMaxSamplesPerPixel));
  command->add_flag(
      "--no-gt", [options](std::int64_t) { options->sequence.ground_truth = false; },
      "Do not write gt/");
  command->add_option("--report", options->report, "JSON report")->check(kOutputFile);
  command->footer(
      "Examples:\n"
      "  glint render scene.json -o seq\n"
      "  glint render scene.json -o preview --frames 10 --width 256 --no-gt\n"
      "  glint render scene.json -o capture --exposure 0.01 --report capture.json\n"
      "  glint render scene.json -o bounced --bounces 3 --indirect-samples 64");
  command->callback([options] { run_render(*options); });
}

}  // namespace glint::app
