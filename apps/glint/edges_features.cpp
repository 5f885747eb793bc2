// glint edges features: the BoundED feature matrix of a cloud, for analysis or other learners.
#include <fmt/format.h>

#include <array>
#include <filesystem>
#include <memory>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "edges/features.h"
#include "io/atomic_file.h"
#include "io/npy.h"
#include "io/point_cloud_io.h"

namespace glint::app {
namespace {

struct FeaturesOptions {
  std::string input;
  std::string output;
  std::vector<int> scales{128, 64, 32, 16};
  bool angular_gap = false;
  bool area_weights = false;
};

constexpr std::array<const char*, edges::kAngularGapFeature + 1> kFeatureNames = {
    "sigma_upper1", "sigma_upper2", "sigma_upper3", "sigma_lower1", "sigma_lower2",
    "sigma_lower3", "d_perp",       "d_parallel",   "s_perp",       "s_parallel",
    "c_perp",       "c_parallel",   "angular_gap"};

void write_csv(const std::string& path, const edges::FeatureMatrix& features,
               const std::vector<int>& scales) {
  io::AtomicFile file(path, false);
  std::ostream& out = file.stream();
  for (std::size_t s = 0; s < scales.size(); ++s) {
    for (int f = 0; f < features.per_scale; ++f) {
      out << (s == 0 && f == 0 ? "" : ",") << "k" << scales[s] << "_" << kFeatureNames[f];
    }
  }
  out << "\n";
  for (std::size_t i = 0; i < features.points; ++i) {
    const float* row = features.row(i);
    for (std::size_t j = 0; j < features.row_size(); ++j) out << (j ? "," : "") << row[j];
    out << "\n";
  }
  file.commit();
}

void run_features(const FeaturesOptions& options) {
  const std::string extension = std::filesystem::path(options.output).extension().string();
  if (extension != ".npy" && extension != ".csv") {
    throw Error(options.output, "", "the output must be .npy (float32) or .csv");
  }
  const PointCloud cloud = io::read_point_cloud(options.input);
  edges::FeatureParams params;
  params.scales = options.scales;
  params.angular_gap = options.angular_gap;
  params.area_weights = options.area_weights;
  edges::FeatureMatrix features;
  try {
    features = edges::compute_features(cloud, params);
  } catch (const Error& e) {
    throw Error(options.input, e.element(), e.reason());
  }
  if (extension == ".npy") {
    io::write_npy(options.output, {features.points, features.row_size()}, features.values.data());
  } else {
    write_csv(options.output, features, options.scales);
  }
  fmt::print("{}: {} points x {} scales x {} features -> {}\n", options.input, features.points,
             features.scales, features.per_scale, options.output);
}

}  // namespace

void register_edges_features(CLI::App& edges) {
  auto options = std::make_shared<FeaturesOptions>();
  CLI::App* command = edges.add_subcommand(
      "features",
      "Compute BoundED's multi-scale neighbourhood features (thesis eqs. 5.1-5.21): per point\n"
      "and scale sigma_upper(3), sigma_lower(3), d_perp, d_parallel, s_perp, s_parallel,\n"
      "c_perp, c_parallel, in the normalised frame of eq. 5.4 (with --angular-gap also\n"
      "angular_gap). Columns are scale-major.\n"
      "Example: glint edges features cloud.ply -o cloud_features.npy");
  command->add_option("input", options->input, "Input point cloud")->required();
  command->add_option("-o,--output", options->output, "Output .npy (float32) or .csv")
      ->required()
      ->check(kOutputFile);
  command->add_option("--scales", options->scales, "Neighbourhood sizes, largest first")
      ->delimiter(',')
      ->capture_default_str();
  command->add_flag("--angular-gap", options->angular_gap,
                    "Add angular_gap per scale: the largest empty sector of the neighbours around "
                    "the normal, as a fraction of the turn (the shipped 3-class model's 13th "
                    "input)");
  command->add_flag("--area-weights", options->area_weights,
                    "Weigh each neighbour by the surface it stands for (as a model trained with "
                    "edges train --area-weights; docs/edges.md \"features\")");
  command->callback([options] { run_features(*options); });
}

}  // namespace glint::app
