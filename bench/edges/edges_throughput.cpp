// End-to-end BoundED throughput: features (kNN included) and classification of a synthetic
// N-point cloud, and the time for every cloud of a folder (default: default-eval).
// Writes JSON (stdout, or --json FILE) with the machine and the parameters it ran with.
//
//   edges_throughput [--points 1000000] [--model models/bounded-3c.json] [--data DIR] [--json F]
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <thread>

#include "core/timer.h"
#include "edges/covariance_baseline.h"
#include "edges/features.h"
#include "edges/model.h"
#include "io/point_cloud_io.h"

namespace {

// Uniform samples on the surfaces of a few boxes and a sphere: edges, corners and curvature.
glint::PointCloud synthetic_cloud(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  glint::PointCloud cloud;
  cloud.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 4 == 3) {  // sphere of radius 0.5 at (3, 0, 0)
      float x = g(rng), y = g(rng), z = g(rng);
      const float r = std::sqrt(x * x + y * y + z * z);
      cloud.push_back(3.f + 0.5f * x / r, 0.5f * y / r, 0.5f * z / r);
      continue;
    }
    const float offset = float(i % 3) * 1.5f;  // three unit boxes in a row
    const int face = static_cast<int>(u(rng) * 6) % 6;
    float p[3] = {u(rng), u(rng), u(rng)};
    p[face / 2] = float(face % 2);
    cloud.push_back(p[0] + offset - 1.5f, p[1], p[2]);
  }
  return cloud;
}

long peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024;
}

std::string arg_value(int argc, char** argv, const std::string& name, const std::string& fallback) {
  for (int i = 1; i + 1 < argc; ++i) {
    if (argv[i] == name) return argv[i + 1];
  }
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t points = std::stoull(arg_value(argc, argv, "--points", "1000000"));
  const std::string model_path = arg_value(argc, argv, "--model", "models/bounded-3c.json");
  const char* env_data = std::getenv("GLINT_DATA");
  const std::string data_root = arg_value(argc, argv, "--data", env_data ? env_data : "../shared/data");
  const std::string folder =
      arg_value(argc, argv, "--folder", data_root + "/pointclouds/default-eval");
  const std::string json_path = arg_value(argc, argv, "--json", "");

  nlohmann::json report;
  report["machine"] = {{"hardware_threads", std::thread::hardware_concurrency()}};
  report["parameters"] = {{"points", points}, {"model", model_path}, {"folder", folder}};

  const glint::edges::Model model = glint::edges::Model::load(model_path);
  glint::edges::FeatureParams feature_params;
  feature_params.scales = model.config.scales;

  const glint::PointCloud cloud = synthetic_cloud(points, 1);
  glint::Stopwatch watch;
  const glint::edges::FeatureMatrix features = glint::edges::compute_features(cloud, feature_params);
  const double features_s = watch.elapsed_s();
  watch.restart();
  std::vector<float> probabilities;
  std::vector<std::uint8_t> labels;
  model.predict(features, probabilities, labels);
  const double classify_s = watch.elapsed_s();
  report["synthetic"] = {{"points", points},
                         {"features_s", features_s},
                         {"inference_s", classify_s},
                         {"total_s", features_s + classify_s},
                         {"points_per_s", double(points) / (features_s + classify_s)},
                         {"peak_rss_mib", peak_rss_mib()}};

  watch.restart();
  const auto ca = glint::edges::classify_covariance_baseline(cloud);
  report["synthetic"]["covariance_baseline_s"] = watch.elapsed_s();

  if (std::filesystem::is_directory(folder)) {
    double total_s = 0, io_s = 0;
    std::size_t total_points = 0, files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      if (entry.path().extension() != ".ply") continue;
      glint::Stopwatch io_watch;
      const glint::PointCloud eval_cloud = glint::io::read_point_cloud(entry.path().string());
      io_s += io_watch.elapsed_s();
      glint::Stopwatch eval_watch;
      const auto eval_features = glint::edges::compute_features(eval_cloud, feature_params);
      model.predict(eval_features, probabilities, labels);
      total_s += eval_watch.elapsed_s();
      total_points += eval_cloud.size();
      ++files;
    }
    report["folder"] = {{"files", files},
                        {"points", total_points},
                        {"features_and_classification_s", total_s},
                        {"io_s", io_s},
                        {"thesis_gpu_s", 1.0}};
  }
  const std::string text = report.dump(2);
  if (json_path.empty()) {
    std::cout << text << "\n";
  } else {
    std::ofstream(json_path) << text << "\n";
    std::cout << text << "\n";
  }
  return 0;
}
