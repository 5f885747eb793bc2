// End-to-end BoundED throughput: features (kNN included) and classification of a generated
// N-point cloud with the peak memory, the neighbour search alone (and an area-weighted model's
// spacing pass alone), the rate of plain nanoflann k-d tree queries at the largest scale
// (k = 128) on the same cloud, and the time for every cloud of a folder (default: default-eval).
// Writes JSON (stdout, or --json FILE) with the machine and the parameters it ran with.
//
//   edges_throughput [--points 1000000] [--model MODEL] [--data DIR] [--json F] [--repeat 1]
// MODEL defaults to the shipped bounded-3c.json (the models folder, as glint finds it).
// --repeat N classifies and searches N times and reports the median (and every run): on a
// shared host single runs of the same binary vary by a quarter.

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/parallel.h"
#include "core/resources.h"
#include "core/timer.h"
#include "edges/classifier.h"
#include "edges/covariance_baseline.h"
#include "edges/features.h"
#include "edges/model.h"
#include "edges/synth.h"
#include "geometry/kdtree.h"
#include "geometry/neighbourhoods.h"
#include "io/json_report.h"
#include "io/point_cloud_io.h"
#include "support/machine.h"

namespace {

// A dense scan-like cloud: one fractal cube from the training-data generator, clean, uniform.
glint::PointCloud benchmark_cloud(std::size_t n) {
  glint::edges::SynthParams params;
  params.seed = 2026;
  params.shapes = {glint::edges::SynthShape::fractal_cube};
  params.min_points = params.max_points = static_cast<int>(n);
  params.noise_levels = {0.0};
  params.outlier_probability = params.abc_probability = params.gradient_probability = 0.0;
  return glint::edges::synthesize_cloud(params, 0).cloud;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string arg_value(int argc, char** argv, const std::string& name, const std::string& fallback) {
  for (int i = 1; i + 1 < argc; ++i) {
    if (argv[i] == name) return argv[i + 1];
  }
  return fallback;
}

// A whole-number option; a value that is not one is an error naming the option.
std::size_t count_value(int argc, char** argv, const std::string& name, std::size_t fallback) {
  const std::string value = arg_value(argc, argv, name, std::to_string(fallback));
  std::size_t used = 0;
  unsigned long long count = 0;
  try {
    count = std::stoull(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size() || value.front() == '-')
    throw std::runtime_error(name + ": '" + value + "' is not a whole number");
  return static_cast<std::size_t>(count);
}

int run(int argc, char** argv) {
  const std::size_t points = count_value(argc, argv, "--points", 1000000);
  const std::string model_path =
      arg_value(argc, argv, "--model", glint::model_path("bounded-3c.json").string());
  const char* env_data = std::getenv("GLINT_DATA");
  const std::string data_root =
      arg_value(argc, argv, "--data", env_data ? env_data : "../shared/data");
  const std::string folder =
      arg_value(argc, argv, "--folder", data_root + "/pointclouds/default-eval");
  const std::string json_path = arg_value(argc, argv, "--json", "");
  const int repeat =
      static_cast<int>(std::max<std::size_t>(1, count_value(argc, argv, "--repeat", 1)));

  nlohmann::json report;
  report["machine"] = {{"cpu", glint::bench::cpu_model()},
                       {"hardware_threads", std::thread::hardware_concurrency()}};
  report["parameters"] = {
      {"points", points}, {"model", model_path}, {"folder", folder}, {"repeat", repeat}};

  const glint::edges::Model model = glint::edges::Model::load(model_path);

  const glint::PointCloud cloud = benchmark_cloud(points);
  const double rss_before_mib = glint::bench::peak_rss_mib();
  std::vector<double> features_runs, inference_runs, total_runs, search_runs, spacing_runs;
  for (int run = 0; run < repeat; ++run) {
    const glint::edges::Classification result = glint::edges::classify(cloud, model);
    features_runs.push_back(result.features_s);
    inference_runs.push_back(result.inference_s);
    total_runs.push_back(result.features_s + result.inference_s);

    // The neighbourhood search alone (the features' visitor replaced by a checksum), so the
    // split between search and features is measured rather than guessed.
    glint::geometry::NeighbourhoodParams search;
    search.k = model.config.scales.front();
    std::atomic<std::uint64_t> checksum{0};
    const glint::Stopwatch search_watch;
    glint::geometry::for_each_neighbourhood(cloud, search, [&](const auto& neighbourhood) {
      checksum.fetch_add(neighbourhood.indices[neighbourhood.size - 1], std::memory_order_relaxed);
    });
    search_runs.push_back(search_watch.elapsed_s());

    // An area-weighted model's spacing pass alone on the search's grid (part of features_s).
    if (model.config.area_weights) {
      const glint::geometry::NeighbourhoodSearch grid(cloud, search);
      const glint::Stopwatch spacing_watch;
      grid.kth_nearest_squared_distances(glint::edges::kAreaSpacingNeighbour + 1);
      spacing_runs.push_back(spacing_watch.elapsed_s());
    }
  }
  const double total_s = median(total_runs);
  report["generated"] = {{"points", points},
                         {"features_s", median(features_runs)},
                         {"inference_s", median(inference_runs)},
                         {"total_s", total_s},
                         {"points_per_s", double(points) / total_s},
                         {"search_only_s", median(search_runs)},
                         {"total_s_runs", total_runs},
                         {"search_only_s_runs", search_runs},
                         {"peak_rss_mib", glint::bench::peak_rss_mib()},
                         {"peak_rss_before_features_mib", rss_before_mib}};
  if (!spacing_runs.empty()) {
    report["generated"]["spacings_only_s"] = median(spacing_runs);
    report["generated"]["spacings_only_s_runs"] = spacing_runs;
  }

  const glint::Stopwatch watch;
  glint::edges::classify_covariance_baseline(cloud);
  report["generated"]["covariance_baseline_s"] = watch.elapsed_s();

  // The peer for the neighbourhood search: nanoflann (via glint's KdTree) answering k = 128
  // queries in parallel, results discarded (BoundED's search hands each list to the features
  // instead of storing 1M × 128 of them). Every 10th point is queried: the rate is the same and
  // the run stays short.
  {
    constexpr int k = 128;
    constexpr std::size_t stride = 10;
    const std::size_t queries = points / stride;
    const glint::Stopwatch build_watch;
    const glint::geometry::KdTree tree(cloud);
    const double build_s = build_watch.elapsed_s();
    const glint::Stopwatch query_watch;
    glint::parallel_for_chunks(queries, 256, [&](std::size_t begin, std::size_t end) {
      std::vector<std::uint32_t> indices(k);
      std::vector<float> distances(k);
      for (std::size_t q = begin; q < end; ++q) {
        const std::size_t i = q * stride;
        const float query[3] = {cloud.x[i], cloud.y[i], cloud.z[i]};
        tree.knn(query, k, indices.data(), distances.data());
      }
    });
    const double query_s = query_watch.elapsed_s();
    report["nanoflann_knn128"] = {{"queries", queries},
                                  {"build_s", build_s},
                                  {"query_s", query_s},
                                  {"queries_per_s", double(queries) / query_s}};
  }

  if (std::filesystem::is_directory(folder)) {
    double folder_s = 0, io_s = 0;
    std::size_t total_points = 0, files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      if (entry.path().extension() != ".ply") continue;
      glint::Stopwatch io_watch;
      const glint::PointCloud eval_cloud = glint::io::read_point_cloud(entry.path().string());
      io_s += io_watch.elapsed_s();
      const glint::edges::Classification eval = glint::edges::classify(eval_cloud, model);
      folder_s += eval.features_s + eval.inference_s;
      total_points += eval_cloud.size();
      ++files;
    }
    report["folder"] = {{"files", files},
                        {"points", total_points},
                        {"features_and_classification_s", folder_s},
                        {"io_s", io_s},
                        {"thesis_gpu_s", 1.0}};
  }
  if (!json_path.empty()) glint::io::write_json(json_path, report);
  std::cout << report.dump(2) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // One line and a non-zero exit for a missing model or data folder, a bad number.
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "edges_throughput: error: " << e.what() << "\n";
    return 1;
  }
}
