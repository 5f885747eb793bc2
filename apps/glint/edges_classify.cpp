// glint edges classify: per-point non-edge / sharp-edge / boundary labels for one cloud.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/timer.h"
#include "edges/angle_gap_baseline.h"
#include "edges/classifier.h"
#include "io/json_report.h"
#include "io/ply.h"
#include "io/point_cloud_io.h"
#include "point_preview.h"

namespace glint::app {
namespace {

struct ClassifyOptions {
  std::string input;
  std::string output;
  std::string model;
  std::string png;
  std::string report;
  std::vector<int> scales;
  std::string method = "bounded";
};

// The angle-gap baseline as a Classification: labels 0 / 2, p_boundary 0 / 1, no sharp class.
edges::Classification classify_angle_gap(const PointCloud& cloud) {
  const Stopwatch watch;
  edges::Classification result;
  result.labels = edges::classify_angle_gap(cloud);
  result.p_sharp.assign(cloud.size(), 0.f);
  result.p_boundary.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) result.p_boundary[i] = result.labels[i] == 2;
  result.features_s = watch.elapsed_s();
  return result;
}

void run_classify(const ClassifyOptions& options) {
  if (std::filesystem::path(options.output).extension() != ".ply") {
    throw Error(options.output, "", "the output must be a .ply file");
  }
  PointCloud cloud = io::read_point_cloud(options.input);
  const std::string model_path = options.model.empty() ? default_edges_model() : options.model;
  const edges::Model model = edges::Model::load(model_path);
  log().info("{}: {} points; model {} ({} classes, scales {})", options.input, cloud.size(),
             model_path, model.config.classes, fmt::join(model.config.scales, ","));

  edges::Classification result;
  try {
    result = options.method == "angle-gap" ? classify_angle_gap(cloud)
                                           : edges::classify(cloud, model, options.scales);
  } catch (const Error& e) {
    throw Error(options.input, e.element(), e.reason());
  }
  edges::attach_classification(cloud, result);
  io::write_ply(options.output, cloud);

  std::size_t counts[3] = {0, 0, 0};
  for (const auto label : result.labels) ++counts[std::min<int>(label, 2)];
  const double total_s = result.features_s + result.inference_s;
  fmt::print(
      "{}: {} points -> {} non-edge, {} sharp, {} boundary in {:.3f} s "
      "(features {:.3f} s, network {:.3f} s, {:.0f} points/s) -> {}\n",
      options.input, cloud.size(), counts[0], counts[1], counts[2], total_s, result.features_s,
      result.inference_s, double(cloud.size()) / total_s, options.output);

  if (!options.png.empty()) {
    write_point_preview(options.png, cloud);
    fmt::print("picture -> {}\n", options.png);
  }
  if (!options.report.empty()) {
    io::write_json(
        options.report,
        {{"command", command_line()},
         {"input", options.input},
         {"output", options.output},
         {"method", options.method},
         {"model", model_path},
         {"scales", options.scales.empty() ? model.config.scales : options.scales},
         {"points", cloud.size()},
         {"labels", {{"non_edge", counts[0]}, {"sharp", counts[1]}, {"boundary", counts[2]}}},
         {"timings_s",
          {{"features", result.features_s}, {"network", result.inference_s}, {"total", total_s}}},
         {"points_per_s", double(cloud.size()) / total_s}});
  }
}

}  // namespace

void register_edges_classify(CLI::App& edges) {
  auto options = std::make_shared<ClassifyOptions>();
  CLI::App* command = edges.add_subcommand(
      "classify",
      "Label every point as non-edge (0), sharp edge (1) or boundary (2).\n"
      "Reads PLY, XYZ/PTS/TXT or PCD; only positions are used (no normals needed).\n"
      "Writes a binary PLY with uchar scalar_label, float scalar_p_sharp, float\n"
      "scalar_p_boundary (CloudCompare shows scalar_* as scalar fields) and red/green/blue\n"
      "(red = sharp, green = boundary) besides the input's own properties.\n"
      "Example: glint edges classify scan.ply -o scan_edges.ply --png scan_edges.png");
  command->add_option("input", options->input, "Input point cloud")->required();
  command->add_option("-o,--output", options->output, "Output PLY")->required()->check(kOutputFile);
  command->add_option("--model", options->model,
                      "Model JSON (default: the shipped 3-class models/bounded-3c.json; "
                      "models/bounded-2c.json has no boundary class)");
  command
      ->add_option("--scales", options->scales,
                   "Override the model's neighbourhood sizes, largest first, e.g. 256,128,64,32 "
                   "for a cloud much denser than the training data")
      ->delimiter(',');
  command
      ->add_option("--method", options->method,
                   "bounded: the network; angle-gap: the boundary-only baseline of PCL and "
                   "Open3D (gap > 90 degrees among neighbours within 1.5 point spacings)")
      ->check(CLI::IsMember({"bounded", "angle-gap"}))
      ->capture_default_str();
  command->add_option("--png", options->png, "Also draw the labelled cloud to this PNG");
  command->add_option("--report", options->report, "Write a JSON report (counts, timings)")
      ->check(kOutputFile);
  command->callback([options] { run_classify(*options); });
}

}  // namespace glint::app
