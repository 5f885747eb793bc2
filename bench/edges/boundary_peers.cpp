// glint's angle-gap boundary baseline beside the real PCL BoundaryEstimation and Open3D
// ComputeBoundaryPoints on the same clouds: agreement of the boundary labels and time.
// Built only where Debian's libpcl-dev and libopen3d-dev are installed; glint never links them.
//
// All three apply the same rule (largest angular gap of the radius neighbours around the PCA
// normal > π/2). To compare like with like, every method gets one fixed radius per cloud:
// 1.5 × the cloud's median local spacing (spacing = r16·sqrt(π/16), as glint's adaptive
// radius uses per point), normals from the 16 nearest neighbours, and a neighbour cap of 64.
// glint's adaptive default (per-point radius) is reported beside it.
//
//   boundary_peers CLOUD_OR_FOLDER... [--json F]

#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/PointCloud.h>
#include <pcl/features/boundary.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <thread>

#include "core/error.h"
#include "core/timer.h"
#include "edges/angle_gap_baseline.h"
#include "geometry/neighbourhoods.h"
#include "io/json_report.h"
#include "io/point_cloud_io.h"
#include "support/machine.h"

namespace {

using glint::PointCloud;
using Mask = std::vector<std::uint8_t>;  // 1 = boundary

constexpr int kNormalNeighbours = 16;
constexpr int kMaxNeighbours = 64;

double median_spacing(const PointCloud& cloud) {
  std::vector<float> spacing(cloud.size());
  glint::geometry::NeighbourhoodParams params;
  params.k = kNormalNeighbours;
  glint::geometry::for_each_neighbourhood(cloud, params, [&](const auto& nb) {
    const int last = nb.size - 1;
    const float r = std::sqrt(nb.dx[last] * nb.dx[last] + nb.dy[last] * nb.dy[last] +
                              nb.dz[last] * nb.dz[last]);
    spacing[nb.point] = r * std::sqrt(std::numbers::pi_v<float> / kNormalNeighbours);
  });
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  return spacing[spacing.size() / 2];
}

Mask run_glint(const PointCloud& cloud, double radius) {
  glint::edges::AngleGapParams params;
  params.k = radius > 0 ? kMaxNeighbours : kNormalNeighbours;
  params.radius = radius;
  const auto labels = glint::edges::classify_angle_gap(cloud, params);
  Mask mask(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i) mask[i] = labels[i] == 2;
  return mask;
}

Mask run_pcl(const PointCloud& cloud, double radius) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  points->resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    (*points)[i] = pcl::PointXYZ(cloud.x[i], cloud.y[i], cloud.z[i]);
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> normal_estimation(
      std::max(1u, std::thread::hardware_concurrency()));
  normal_estimation.setInputCloud(points);
  normal_estimation.setSearchMethod(tree);
  normal_estimation.setKSearch(kNormalNeighbours);
  normal_estimation.compute(*normals);

  pcl::BoundaryEstimation<pcl::PointXYZ, pcl::Normal, pcl::Boundary> boundary_estimation;
  boundary_estimation.setInputCloud(points);
  boundary_estimation.setInputNormals(normals);
  boundary_estimation.setSearchMethod(tree);
  boundary_estimation.setRadiusSearch(radius);
  boundary_estimation.setAngleThreshold(std::numbers::pi / 2);
  pcl::PointCloud<pcl::Boundary> boundaries;
  boundary_estimation.compute(boundaries);
  Mask mask(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) mask[i] = boundaries[i].boundary_point != 0;
  return mask;
}

Mask run_open3d(const PointCloud& cloud, double radius) {
  std::vector<float> xyz(cloud.size() * 3);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    xyz[3 * i] = cloud.x[i], xyz[3 * i + 1] = cloud.y[i], xyz[3 * i + 2] = cloud.z[i];
  }
  const open3d::core::Tensor positions(xyz, {static_cast<int64_t>(cloud.size()), 3},
                                       open3d::core::Float32);
  open3d::t::geometry::PointCloud points(positions);
  points.EstimateNormals(kNormalNeighbours);
  const auto [boundary, tensor_mask] = points.ComputeBoundaryPoints(radius, kMaxNeighbours, 90.0);
  const bool* values = tensor_mask.To(open3d::core::Bool).Contiguous().GetDataPtr<bool>();
  return Mask(values, values + cloud.size());
}

// Matthews correlation of two boolean labelings (one as truth), 0 when undefined.
double mcc(const Mask& a, const Mask& b) {
  double tp = 0, tn = 0, fp = 0, fn = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    tp += a[i] && b[i], tn += !a[i] && !b[i], fp += !a[i] && b[i], fn += a[i] && !b[i];
  }
  const double d = std::sqrt((tp + fp) * (tp + fn) * (tn + fp) * (tn + fn));
  return d > 0 ? (tp * tn - fp * fn) / d : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "glint angle-gap baseline vs PCL BoundaryEstimation and Open3D "
      "ComputeBoundaryPoints; writes JSON"};
  std::vector<std::string> inputs;
  std::string json_path;
  app.add_option("clouds", inputs, "Point clouds or folders of .ply")->required();
  app.add_option("--json", json_path, "Output (default stdout)");
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> files;
  for (const auto& input : inputs) {
    if (!std::filesystem::is_directory(input)) {
      files.push_back(input);
      continue;
    }
    for (const auto& entry : std::filesystem::directory_iterator(input))
      if (entry.path().extension() == ".ply") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());

  nlohmann::json report;
  report["machine"] = {{"cpu", glint::bench::cpu_model()},
                       {"hardware_threads", std::thread::hardware_concurrency()}};
  report["parameters"] = {{"radius", "1.5 x median local spacing (r16 sqrt(pi/16))"},
                          {"normal_neighbours", kNormalNeighbours},
                          {"max_neighbours", kMaxNeighbours},
                          {"angle_threshold_deg", 90}};
  report["clouds"] = nlohmann::json::array();
  try {
    for (const auto& file : files) {
      const PointCloud cloud = glint::io::read_point_cloud(file);
      const double radius = 1.5 * median_spacing(cloud);
      nlohmann::json row = {{"file", file}, {"points", cloud.size()}, {"radius", radius}};
      auto timed = [&](const char* name, auto run) {
        const glint::Stopwatch watch;
        Mask mask = run();
        row[name] = {{"seconds", watch.elapsed_s()},
                     {"boundary_points", std::count(mask.begin(), mask.end(), 1)}};
        return mask;
      };
      const Mask glint_fixed =
          timed("glint_fixed_radius", [&] { return run_glint(cloud, radius); });
      const Mask glint_adaptive = timed("glint_adaptive", [&] { return run_glint(cloud, 0.0); });
      const Mask pcl = timed("pcl", [&] { return run_pcl(cloud, radius); });
      const Mask open3d = timed("open3d", [&] { return run_open3d(cloud, radius); });
      auto agreement = [&](const Mask& a, const Mask& b) {
        std::size_t same = 0;
        for (std::size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
        return nlohmann::json{{"same_label", double(same) / double(a.size())}, {"mcc", mcc(a, b)}};
      };
      row["agreement"] = {{"glint_fixed_vs_pcl", agreement(pcl, glint_fixed)},
                          {"glint_fixed_vs_open3d", agreement(open3d, glint_fixed)},
                          {"pcl_vs_open3d", agreement(pcl, open3d)},
                          {"glint_adaptive_vs_pcl", agreement(pcl, glint_adaptive)}};
      std::cerr << file << ": " << row["agreement"].dump() << "\n";
      report["clouds"].push_back(row);
    }
  } catch (const glint::Error& e) {
    std::cerr << "boundary_peers: " << e.what() << "\n";
    return 1;
  }
  report["peak_rss_mib"] = glint::bench::peak_rss_mib();
  if (!json_path.empty()) glint::io::write_json(json_path, report);
  std::cout << report.dump(2) << "\n";
  return 0;
}
