// Speed of the synthetic-data renderer: frames per second of the
// built-in `bunnies` scene at 512x424 with and without shadow rays, and the time to generate
// the default training set, measured on its first --training-sequences sequences and
// extrapolated linearly (every sequence is drawn from the same distribution).
// Writes JSON (stdout, or --json FILE).
//
//   render_speed [--data DIR] [--frames 30] [--threads N] [--training-sequences 40] [--json F]

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "core/parallel.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/json_report.h"
#include "render/builtin_scenes.h"
#include "render/renderer.h"
#include "render/training_set.h"
#include "support/machine.h"

namespace {

using namespace glint;

// Renders `frames` poses of the trajectory (after one warm-up frame); rendering only.
nlohmann::json scene_speed(render::Scene scene, bool shadows, int frames) {
  scene.shadows = shadows;
  Stopwatch build_watch;
  const render::Renderer renderer(scene);
  const double build_seconds = build_watch.elapsed_s();
  renderer.render(scene.trajectory.front(), 0);
  const int poses = static_cast<int>(scene.trajectory.size());
  Stopwatch watch;
  for (int i = 0; i < frames; ++i) renderer.render(scene.trajectory[i % poses], i);
  const double seconds = watch.elapsed_s();
  return {{"shadows", shadows},
          {"frames", frames},
          {"scene_build_seconds", build_seconds},
          {"ms_per_frame", 1000 * seconds / frames},
          {"frames_per_second", frames / seconds}};
}

// Times each of the first `measured_sequences` sequences, separately for those with and without
// an environment map (the expensive kind), and extrapolates with the set's environment share.
nlohmann::json training_set_speed(const std::string& data_dir, int measured_sequences) {
  render::TrainingSetParams params;
  params.data_dir = data_dir;
  const int default_sequences = params.sequences;
  params.sequences = measured_sequences;
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / "glint_render_speed_training";
  std::filesystem::remove_all(out);
  std::vector<double> finished_s;
  Stopwatch watch;
  const render::TrainingSetStats stats = render::write_training_set(
      params, out.string(), [&] { finished_s.push_back(watch.elapsed_s()); });
  std::filesystem::remove_all(out);
  double seconds[2] = {0, 0};  // without, with an environment map
  int counts[2] = {0, 0};
  for (int i = 0; i < measured_sequences; ++i) {
    const int kind = render::make_training_scene(params, i).environment.has_value();
    seconds[kind] += finished_s[i] - (i > 0 ? finished_s[i - 1] : 0.0);
    ++counts[kind];
  }
  const double plain = counts[0] ? seconds[0] / counts[0] : 0;
  const double lit_by_map = counts[1] ? seconds[1] / counts[1] : plain;
  const double p = params.environment_probability;
  const double expected_per_sequence = (1 - p) * plain + p * lit_by_map;
  return {{"default_parameters", render::training_set_parameters_json(params)},
          {"default_sequences", default_sequences},
          {"measured_sequences", measured_sequences},
          {"measured_seconds", stats.seconds},
          {"measured_with_environment", counts[1]},
          {"seconds_per_sequence_without_environment", plain},
          {"seconds_per_sequence_with_environment", lit_by_map},
          {"expected_seconds_per_sequence", expected_per_sequence},
          {"extrapolated_default_set_minutes", expected_per_sequence * default_sequences / 60}};
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = render::default_data_dir(), json_path;
  int frames = 30, threads = 0, training_sequences = 40;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--data")
      data_dir = argv[i + 1];
    else if (flag == "--frames")
      frames = std::stoi(argv[i + 1]);
    else if (flag == "--threads")
      threads = std::stoi(argv[i + 1]);
    else if (flag == "--training-sequences")
      training_sequences = std::stoi(argv[i + 1]);
    else if (flag == "--json")
      json_path = argv[i + 1];
    else {
      std::cerr << "usage: render_speed [--data DIR] [--frames N] [--threads N] "
                   "[--training-sequences N] [--json F]\n";
      return 2;
    }
  }
  set_quiet(true);
  const auto thread_limit = limit_threads(threads);
  nlohmann::json result{
      {"cpu", bench::cpu_model()},
      {"hardware_threads", std::thread::hardware_concurrency()},
      {"threads", threads > 0 ? threads : int(std::thread::hardware_concurrency())},
      {"data", data_dir}};

  render::BuiltinOptions options;
  options.data_dir = data_dir;
  const render::Scene bunnies = render::make_builtin_scene("bunnies", options);
  result["bunnies"] = {
      {"width", options.width},
      {"height", options.height},
      {"lights", bunnies.lights.size()},
      {"runs", {scene_speed(bunnies, true, frames), scene_speed(bunnies, false, frames)}}};
  if (training_sequences > 0)
    result["training_set"] = training_set_speed(data_dir, training_sequences);

  result["peak_rss_mib"] = bench::peak_rss_mib();
  if (json_path.empty())
    std::cout << result.dump(2) << "\n";
  else
    io::write_json(json_path, result);
  return 0;
}
