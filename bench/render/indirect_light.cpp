// The renderer's indirect light (Scene::bounces) on the built-in scenes:
//  - how much light each bounce adds: mean radiance over the objects' pixels (floor and walls
//    excluded) and over every surface pixel with 0..max bounces, on `poses` trajectory poses
//    at the study resolution;
//  - noise against paths per pixel: the indirect part's per-pixel RMS error relative to its
//    mean, and the RMS error of the exposed 8-bit sRGB code values (what the pipeline reads),
//    over the objects' pixels of pose 0 at `bounces`, against a `reference`-path image (the
//    reference's own variance, 1/reference of one path's, is taken out);
//  - rendering time per frame at the full 512x424 for direct light (shadows on) and for
//    `bounces` at each timed path count.
// Writes JSON (stdout, or --json FILE).
//
//   indirect_light [--data DIR] [--scenes bunnies,office] [--poses 3] [--max-bounces 4]
//                  [--bounces 3] [--study-width 128] [--samples 1,2,4,8,16,32,64]
//                  [--reference 256] [--timed 4,16] [--threads N] [--json F]

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/parallel.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/json_report.h"
#include "render/builtin_scenes.h"
#include "render/renderer.h"
#include "render/sensor.h"
#include "support/machine.h"

namespace {

using namespace glint;

std::vector<int> integers(const std::string& list) {
  std::vector<int> out;
  std::stringstream stream(list);
  for (std::string item; std::getline(stream, item, ',');) out.push_back(std::stoi(item));
  return out;
}

std::vector<std::string> words(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream stream(list);
  for (std::string item; std::getline(stream, item, ',');) out.push_back(item);
  return out;
}

// Object pixels: a segment that is neither the floor nor a wall.
std::vector<std::uint8_t> object_mask(const render::Scene& scene,
                                      const render::FrameBuffers& frame) {
  std::vector<std::uint8_t> mask(frame.segment.pixel_count(), 0);
  for (std::size_t i = 0; i < mask.size(); ++i) {
    const int id = frame.segment.plane(0)[i];
    if (id < 1) continue;
    const std::string& name = scene.objects[id - 1].name;
    mask[i] = name != "floor" && name.find("wall") == std::string::npos;
  }
  return mask;
}

// Mean over pixels (and RGB) where mask is set; every surface pixel when mask is null.
double mean_radiance(const render::FrameBuffers& frame, const std::vector<std::uint8_t>* mask) {
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < frame.radiance.pixel_count(); ++i) {
    if (mask ? !(*mask)[i] : frame.segment.plane(0)[i] < 1) continue;
    for (int c = 0; c < 3; ++c) sum += frame.radiance.plane(c)[i];
    count += 3;
  }
  return count ? sum / count : 0;
}

// User + system time of this process, every thread.
double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

render::Scene with(render::Scene scene, int bounces, int samples) {
  scene.bounces = bounces;
  scene.indirect_samples = std::max(1, samples);
  return scene;
}

nlohmann::json bounce_contributions(const render::Scene& scene, int poses, int max_bounces,
                                    int samples) {
  nlohmann::json rows = nlohmann::json::array();
  for (int bounces = 0; bounces <= max_bounces; ++bounces) {
    const render::Renderer renderer(with(scene, bounces, samples));
    double objects = 0, surfaces = 0;
    for (int p = 0; p < poses; ++p) {
      const int index = int(scene.trajectory.size()) * p / poses;
      const render::FrameBuffers frame = renderer.render(scene.trajectory[index], index);
      const std::vector<std::uint8_t> mask = object_mask(scene, frame);
      objects += mean_radiance(frame, &mask) / poses;
      surfaces += mean_radiance(frame, nullptr) / poses;
    }
    rows.push_back({{"bounces", bounces},
                    {"mean_object_radiance", objects},
                    {"mean_surface_radiance", surfaces}});
  }
  const double direct = rows[0]["mean_object_radiance"];
  for (auto& row : rows)
    row["object_radiance_over_direct"] = double(row["mean_object_radiance"]) / direct;
  return rows;
}

nlohmann::json noise_study(const render::Scene& scene, int bounces,
                           const std::vector<int>& sample_counts, int reference_samples) {
  const Pose& pose = scene.trajectory.front();
  const render::FrameBuffers direct = render::Renderer(with(scene, 0, 1)).render(pose, 0);
  const render::FrameBuffers reference =
      render::Renderer(with(scene, bounces, reference_samples)).render(pose, 0);
  const std::vector<std::uint8_t> mask = object_mask(scene, direct);
  const ImageF reference_8bit = render::expose_colour(reference.radiance, scene.camera, 0, 0);
  double reference_indirect = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < mask.size(); ++i)
    for (int c = 0; c < 3 && mask[i]; ++c, ++count)
      reference_indirect += reference.radiance.plane(c)[i] - direct.radiance.plane(c)[i];
  reference_indirect /= double(count);
  nlohmann::json rows = nlohmann::json::array();
  for (const int samples : sample_counts) {
    Stopwatch watch;
    // Another seed: independent of the reference's paths.
    render::Scene noisy = with(scene, bounces, samples);
    noisy.seed = scene.seed + 1;
    const render::FrameBuffers frame = render::Renderer(noisy).render(pose, 0);
    const double seconds = watch.elapsed_s();
    const ImageF frame_8bit = render::expose_colour(frame.radiance, scene.camera, 0, 0);
    double squared = 0, squared_8bit = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
      for (int c = 0; c < 3 && mask[i]; ++c) {
        const double error = frame.radiance.plane(c)[i] - reference.radiance.plane(c)[i];
        const double error_8bit =
            255.0 * (frame_8bit.plane(c)[i] - double(reference_8bit.plane(c)[i]));
        squared += error * error;
        squared_8bit += error_8bit * error_8bit;
      }
    }
    // Measured variance = sigma_1^2 (1/S + 1/R): keep the 1/S part.
    const double own_share = (1.0 / samples) / (1.0 / samples + 1.0 / reference_samples);
    rows.push_back(
        {{"samples", samples},
         {"indirect_relative_rms", std::sqrt(own_share * squared / count) / reference_indirect},
         {"rgb_8bit_rms_codes", std::sqrt(own_share * squared_8bit / count)},
         {"study_seconds", seconds}});
  }
  return {{"bounces", bounces},
          {"reference_samples", reference_samples},
          {"mean_object_indirect_radiance", reference_indirect},
          {"rows", rows}};
}

nlohmann::json frame_times(const render::Scene& scene, int bounces,
                           const std::vector<int>& sample_counts) {
  nlohmann::json rows = nlohmann::json::array();
  // Wall time and the process's CPU time (all threads): on a shared machine the CPU time is
  // the steadier figure.
  const auto time_one = [&](int b, int samples) {
    const render::Renderer renderer(with(scene, b, samples));
    const double cpu_start = cpu_seconds();
    Stopwatch watch;
    renderer.render(scene.trajectory.front(), 0);
    return nlohmann::json{{"bounces", b},
                          {"samples", samples},
                          {"ms_per_frame", 1000 * watch.elapsed_s()},
                          {"cpu_seconds_per_frame", cpu_seconds() - cpu_start}};
  };
  rows.push_back(time_one(0, 0));
  for (const int samples : sample_counts) rows.push_back(time_one(bounces, samples));
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = render::default_data_dir(), json_path, scenes = "bunnies,office";
  std::string samples = "1,2,4,8,16,32,64", timed = "4,16";
  int poses = 3, max_bounces = 4, bounces = 3, study_width = 128, reference = 256, threads = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--data")
      data_dir = value;
    else if (flag == "--scenes")
      scenes = value;
    else if (flag == "--poses")
      poses = std::stoi(value);
    else if (flag == "--max-bounces")
      max_bounces = std::stoi(value);
    else if (flag == "--bounces")
      bounces = std::stoi(value);
    else if (flag == "--study-width")
      study_width = std::stoi(value);
    else if (flag == "--samples")
      samples = value;
    else if (flag == "--reference")
      reference = std::stoi(value);
    else if (flag == "--timed")
      timed = value;
    else if (flag == "--threads")
      threads = std::stoi(value);
    else if (flag == "--json")
      json_path = value;
    else {
      std::cerr << "usage: indirect_light [--data DIR] [--scenes bunnies,office] [--poses 3] "
                   "[--max-bounces 4] [--bounces 3] [--study-width 128] [--samples 1,2,4,...] "
                   "[--reference 256] [--timed 4,16] [--threads N] [--json F]\n";
      return 2;
    }
  }
  set_quiet(true);
  const auto thread_limit = limit_threads(threads);
  nlohmann::json result{
      {"cpu", bench::cpu_model()},
      {"hardware_threads", std::thread::hardware_concurrency()},
      {"threads", threads > 0 ? threads : int(std::thread::hardware_concurrency())},
      {"data", data_dir},
      {"study_width", study_width},
      {"contribution_samples", 32}};
  for (const std::string& name : words(scenes)) {
    render::BuiltinOptions options;
    options.data_dir = data_dir;
    const render::Scene full = render::make_builtin_scene(name, options);
    options.width = study_width;
    options.height = (study_width * 424 + 256) / 512;
    const render::Scene study = render::make_builtin_scene(name, options);
    result[name] = {{"bounce_contributions", bounce_contributions(study, poses, max_bounces, 32)},
                    {"noise", noise_study(study, bounces, integers(samples), reference)},
                    {"frame_times_512x424", frame_times(full, bounces, integers(timed))}};
    std::cerr << name << " done\n";
  }
  result["peak_rss_mib"] = bench::peak_rss_mib();
  if (json_path.empty())
    std::cout << result.dump(2) << "\n";
  else
    io::write_json(json_path, result);
  return 0;
}
