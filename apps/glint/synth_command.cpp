// glint synth: the built-in synthetic sequences of paper 1 §4.2 (cubes, bunnies, office), the
// light-capture sequence (§3.2) and the HemiCNN training set (SynBRDF replacement, §4.1).
#include <fmt/format.h>

#include <memory>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "commands.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/json_report.h"
#include "render/builtin_scenes.h"
#include "render/sequence_writer.h"
#include "render/training_set.h"
#include "synth_preview.h"

namespace glint::app {
namespace {

struct SynthCommandOptions {
  std::string what;  // cubes, bunnies, office, lights or training
  std::string output;
  std::string capture_scene = "bunnies";
  int frames = 0;             // 0: the kind's default
  int width = 0, height = 0;  // 0: the kind's default
  std::uint64_t seed = 1;
  std::string data_dir = render::default_data_dir();
  int sequences = render::TrainingSetParams{}.sequences;
  std::vector<std::string> shapes;  // training: empty = all
  float near_grey_share = render::MaterialRanges{}.near_grey_share;
  bool no_ground_truth = false;
  bool no_shadows = false;
  int bounces = 0;
  int indirect_samples = render::Scene{}.indirect_samples;
  bool preview = false;
  std::string report;
};

// --width alone keeps the Kinect's 512:424 aspect; neither keeps the default size.
std::pair<int, int> image_size(const SynthCommandOptions& options, int default_width,
                               int default_height) {
  const int width = options.width > 0 ? options.width : default_width;
  const int height = options.height > 0  ? options.height
                     : options.width > 0 ? (width * 424 + 256) / 512
                                         : default_height;
  return {width, height};
}

nlohmann::json run_training_set(const SynthCommandOptions& options) {
  render::TrainingSetParams params;
  params.sequences = options.sequences;
  if (options.frames > 0) params.frames = options.frames;
  std::tie(params.width, params.height) = image_size(options, params.width, params.height);
  params.seed = options.seed;
  params.data_dir = options.data_dir;
  params.ground_truth = !options.no_ground_truth;
  params.shapes = options.shapes;
  params.ranges.near_grey_share = options.near_grey_share;
  nlohmann::json report = render::training_set_parameters_json(params);
  if (options.preview) {
    report["render_ms"] =
        write_frame_preview(render::make_training_scene(params, 0), options.output);
    return report;
  }
  ProgressBar progress("training set", static_cast<std::size_t>(params.sequences));
  const render::TrainingSetStats stats =
      render::write_training_set(params, options.output, [&] { progress.advance(); });
  progress.finish();
  log().info("{}: {} sequences of {} frames at {}x{} ({} rendered, {} already there) in {:.1f} s",
             options.output, params.sequences, params.frames, params.width, params.height,
             stats.rendered, stats.skipped, stats.seconds);
  report["sequences"] = params.sequences;
  report["rendered"] = stats.rendered;
  report["skipped"] = stats.skipped;
  report["seconds"] = stats.seconds;
  if (stats.rendered > 0) report["seconds_per_rendered_sequence"] = stats.seconds / stats.rendered;
  return report;
}

nlohmann::json run_scene(const SynthCommandOptions& options) {
  const bool light_capture = options.what == "lights";
  render::BuiltinOptions builtin;
  builtin.data_dir = options.data_dir;
  if (options.frames > 0) builtin.frames = options.frames;
  std::tie(builtin.width, builtin.height) = image_size(options, builtin.width, builtin.height);
  builtin.seed = options.seed;
  render::Scene scene =
      render::make_builtin_scene(light_capture ? options.capture_scene : options.what, builtin);
  if (light_capture) {
    render::LightCaptureParams path;
    if (options.frames > 0) path.frames = options.frames;
    scene = render::make_light_capture(scene, path);
  }
  scene.shadows = !options.no_shadows;
  scene.bounces = options.bounces;
  scene.indirect_samples = options.indirect_samples;
  nlohmann::json report{{"scene", options.what},
                        {"frames", scene.trajectory.size()},
                        {"width", builtin.width},
                        {"height", builtin.height},
                        {"seed", options.seed},
                        {"shadows", scene.shadows},
                        {"bounces", scene.bounces},
                        {"indirect_samples", scene.indirect_samples},
                        {"exposure", scene.camera.exposure}};
  if (light_capture) report["captured_scene"] = options.capture_scene;
  if (options.preview) {
    report["render_ms"] = write_frame_preview(scene, options.output);
    return report;
  }
  render::SequenceOptions sequence;
  sequence.ground_truth = !options.no_ground_truth;
  const render::SequenceStats stats = render::write_sequence(scene, options.output, sequence);
  log().info("{}: {} frames at {}x{} in {:.1f} s ({:.1f} ms rendering per frame)", options.output,
             stats.frames, builtin.width, builtin.height, stats.seconds, stats.median_render_ms);
  report["ground_truth"] = sequence.ground_truth;
  report["seconds"] = stats.seconds;
  report["median_render_ms"] = stats.median_render_ms;
  report["median_frame_ms"] = stats.median_frame_ms;
  return report;
}

void run_synth(const SynthCommandOptions& options) {
  const Stopwatch watch;
  nlohmann::json report =
      options.what == "training" ? run_training_set(options) : run_scene(options);
  if (options.preview)
    log().info("{}: rgb, depth, kd, ks and alpha PNGs of frame 0", options.output);
  if (options.report.empty()) return;
  report["command"] = command_line();
  report["output"] = options.output;
  report["data"] = options.data_dir;
  report["preview"] = options.preview;
  report["total_seconds"] = watch.elapsed_s();
  io::write_json(options.report, report);
}

}  // namespace

void register_synth_command(CLI::App& app) {
  auto options = std::make_shared<SynthCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "synth",
      "Render the synthetic RGB-D sequences of the reflectance paper (cubes, bunnies, office),\n"
      "a scene's light-capture sequence, or the HemiCNN training set, with ground truth.");
  std::vector<std::string> kinds = render::builtin_scene_names();
  kinds.insert(kinds.end(), {"lights", "training"});
  command->add_option("what", options->what, "cubes, bunnies, office, lights or training")
      ->required()
      ->check(CLI::IsMember(kinds));
  command->add_option("-o,--output", options->output, "Sequence folder (training: set folder)")
      ->required();
  command
      ->add_option("--frames", options->frames,
                   "Frames per sequence (default: scenes 300, lights 60, training 30)")
      ->check(kPositive);
  command->add_option("--width", options->width, "Image width (default 512; training 160)")
      ->check(kPositive);
  command->add_option("--height", options->height, "Image height (default: width * 424 / 512)")
      ->check(kPositive);
  command->add_option("--seed", options->seed, "Seed of noise and of the training set")
      ->capture_default_str();
  command->add_option("--data", options->data_dir, "Data folder with meshes/, textures/, envmaps/")
      ->capture_default_str();
  command
      ->add_option("--scene", options->capture_scene, "lights: the scene whose lights to capture")
      ->check(CLI::IsMember(render::builtin_scene_names()))
      ->capture_default_str();
  command->add_option("--sequences", options->sequences, "training: number of sequences")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--shapes", options->shapes,
                   "training: shapes to draw from, comma-separated (default all: sphere, box and "
                   "the meshes of DATA/meshes)")
      ->delimiter(',')
      ->check(CLI::IsMember(render::training_shape_names()));
  command
      ->add_option("--near-grey-share", options->near_grey_share,
                   "training: share of albedos drawn with CIELAB chroma uniform in radius (1: "
                   "near-greys about 11x as common as with a, b uniform in a square)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command->add_flag("--no-gt", options->no_ground_truth, "Do not write the gt/ maps");
  command->add_flag("--no-shadows", options->no_shadows, "Scenes: no shadow rays");
  command
      ->add_option("--bounces", options->bounces,
                   "Scenes: indirect bounces to path trace (0 = direct light only, the "
                   "pipeline's image model; the training set is always direct)")
      ->check(kNonNegative)
      ->capture_default_str();
  command
      ->add_option("--indirect-samples", options->indirect_samples,
                   "Scenes: paths per pixel for the indirect light (noise ~ 1/sqrt(samples))")
      ->check(kPositive)
      ->capture_default_str();
  command->add_flag("--preview", options->preview,
                    "Only frame 0 as PNGs for people: rgb, depth (false colour), kd, ks, alpha");
  command->add_option("--report", options->report, "JSON report with parameters and timings")
      ->check(kOutputFile);
  command->footer(
      "Scenes, materials, lights and cameras are listed in src/render/builtin_scenes.h; the\n"
      "training-set ranges in src/render/training_set.h. Sequences use the format of\n"
      "'glint render' (rgb/, depth/, associations.txt, groundtruth.txt, gt/, scene.json).\n"
      "A training set is OUT/seq_00000 ... plus OUT/index.json; re-running the same command\n"
      "skips complete sequences, and a larger --sequences extends the set.\n"
      "Examples:\n"
      "  glint synth bunnies -o seq/bunnies --frames 1000\n"
      "  glint synth lights --scene bunnies -o seq/bunnies-lights\n"
      "  glint synth office -o seq/office-bounce3 --bounces 3\n"
      "  glint synth office -o pictures/office --preview\n"
      "  glint synth training -o train --sequences 400 --report train.json");
  command->callback([options] { run_synth(*options); });
}

}  // namespace glint::app
