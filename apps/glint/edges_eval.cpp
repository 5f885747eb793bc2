// glint edges eval: thesis §5.5.2 scores of glint models, saved predictions, the
// covariance-analysis baseline and the angle-gap boundary baseline on labelled clouds, per file
// with median and mean.
#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/timer.h"
#include "edges/angle_gap_baseline.h"
#include "edges/classifier.h"
#include "edges/covariance_baseline.h"
#include "edges/metrics.h"
#include "io/json_report.h"
#include "io/point_cloud_io.h"

namespace glint::app {
namespace {

struct EvalOptions {
  std::vector<std::string> ground_truth;
  std::vector<std::string> models;
  std::vector<std::string> predictions;
  std::string task = "sharp";
  edges::CovarianceBaselineParams baseline;
  edges::AngleGapParams angle_gap;
  bool no_baseline = false;
  std::string report;
};

std::vector<std::uint8_t> labels_of(const PointCloud& cloud, const std::string& path,
                                    io::LabelSource source = io::LabelSource::truth) {
  auto labels = io::read_labels(cloud, source);
  if (!labels) throw Error(path, "", "has no label property (label, scalar_label or class)");
  return *labels;
}

// The prediction file for a ground-truth file: same file name inside a folder, or the i-th
// of a list of files.
std::string prediction_for(const std::vector<std::string>& predictions, std::size_t index,
                           const std::string& truth_path) {
  if (predictions.size() == 1 && std::filesystem::is_directory(predictions[0])) {
    const auto path =
        std::filesystem::path(predictions[0]) / std::filesystem::path(truth_path).filename();
    if (!std::filesystem::exists(path)) {
      throw Error(path.string(), "", "no prediction for " + truth_path);
    }
    return path.string();
  }
  return predictions[index];
}

void print_row(const std::string& file, const std::string& method, const edges::BinaryScores& s) {
  fmt::print("{:<36} {:<16} {:>6.3f} {:>6.3f} {:>6.3f} {:>6.3f} {:>6.3f} {:>6.3f}\n", file, method,
             s.precision, s.recall, s.mcc, s.f1, s.accuracy, s.iou);
}

void run_eval(EvalOptions options) {
  const edges::EvalTask task = edges::parse_eval_task(options.task);
  const std::vector<std::string> truth_files = expand_point_cloud_inputs(options.ground_truth);
  if (!options.predictions.empty() &&
      !(options.predictions.size() == 1 && std::filesystem::is_directory(options.predictions[0])) &&
      options.predictions.size() != truth_files.size()) {
    throw Error("", "--pred", "give one prediction file per ground-truth file, or one folder");
  }
  if (options.models.empty() && options.predictions.empty()) {
    options.models.push_back(default_edges_model());
  }
  std::vector<std::pair<std::string, edges::Model>> models;
  for (const auto& path : options.models) {
    models.emplace_back("glint:" + std::filesystem::path(path).stem().string(),
                        edges::Model::load(path));
  }

  std::vector<std::string> methods;
  for (const auto& [name, model] : models) methods.push_back(name);
  if (!options.predictions.empty()) methods.push_back("predictions");
  if (!options.no_baseline) methods.push_back("CA");
  // The angle-gap criterion finds boundaries only: no column for the sharp task.
  const bool run_angle_gap = !options.no_baseline && task != edges::EvalTask::sharp;
  if (run_angle_gap) methods.push_back("angle-gap");
  std::map<std::string, std::vector<edges::BinaryScores>> per_method;
  nlohmann::json files_json = nlohmann::json::array();
  std::vector<std::string> without_positives;  // MCC is undefined there (edges/metrics.h)

  fmt::print("task: {} (positive = {})\n", options.task,
             task == edges::EvalTask::sharp      ? "sharp edge; boundary counts as negative"
             : task == edges::EvalTask::boundary ? "boundary"
                                                 : "sharp edge or boundary");
  fmt::print("{:<36} {:<16} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6}\n", "file", "method", "P", "R",
             "MCC", "F1", "Acc", "IoU");
  for (std::size_t f = 0; f < truth_files.size(); ++f) {
    const std::string& path = truth_files[f];
    const PointCloud cloud = io::read_point_cloud(path);
    const std::vector<std::uint8_t> truth = labels_of(cloud, path);
    const std::string name = std::filesystem::path(path).filename().string();
    if (std::none_of(truth.begin(), truth.end(),
                     [&](std::uint8_t label) { return edges::is_positive(label, task); }))
      without_positives.push_back(name);
    nlohmann::json file_json = {{"file", path}, {"points", cloud.size()}, {"scores", {}}};
    auto record = [&](const std::string& method, const std::vector<std::uint8_t>& predicted,
                      double seconds) {
      const edges::BinaryScores s = edges::score(predicted, truth, task);
      per_method[method].push_back(s);
      print_row(name, method, s);
      file_json["scores"][method] = edges::to_json(s);
      file_json["scores"][method]["seconds"] = seconds;
    };
    try {
      // Ungated models with the same scales and inputs share one feature matrix (features
      // dominate the time); a gated model chooses its network, and so its inputs, first.
      std::map<edges::FeatureParams, std::pair<edges::FeatureMatrix, double>> features_by_inputs;
      for (const auto& [method, model] : models) {
        if (model.gated()) {
          const edges::Classification result = edges::classify(cloud, model);
          record(method, result.labels, result.features_s + result.inference_s);
          file_json["scores"][method]["network"] = edges::network_name(result.gates);
          continue;
        }
        auto [entry, is_new] = features_by_inputs.try_emplace(model.config.feature_params());
        auto& [features, features_s] = entry->second;
        if (is_new) {
          const Stopwatch watch;
          features = edges::compute_features(cloud, model.config.feature_params());
          features_s = watch.elapsed_s();
        }
        const edges::Classification result = edges::classify_features(features, model);
        record(method, result.labels, features_s + result.inference_s);
      }
      if (!options.predictions.empty()) {
        const std::string prediction_path = prediction_for(options.predictions, f, path);
        const PointCloud predicted = io::read_point_cloud(prediction_path);
        record("predictions", labels_of(predicted, prediction_path, io::LabelSource::prediction),
               0.0);
      }
      if (!options.no_baseline) {
        Stopwatch watch;
        const auto labels = edges::classify_covariance_baseline(cloud, options.baseline);
        record("CA", labels, watch.elapsed_s());
      }
      if (run_angle_gap) {
        Stopwatch watch;
        const auto labels = edges::classify_angle_gap(cloud, options.angle_gap);
        record("angle-gap", labels, watch.elapsed_s());
      }
    } catch (const Error& e) {
      throw Error(e.file().empty() ? path : e.file(), e.element(), e.reason());
    }
    files_json.push_back(file_json);
  }

  nlohmann::json summary_json;
  std::map<std::string, edges::ScoreSummary> summaries;
  for (const auto& method : methods) {
    const edges::ScoreSummary& summary = summaries[method] = edges::summarise(per_method[method]);
    summary_json[method] = {{"median", edges::to_json(summary.median)},
                            {"mean", edges::to_json(summary.mean)},
                            {"all_points", edges::to_json(summary.pooled)}};
  }
  for (const auto& method : methods) print_row("median", method, summaries[method].median);
  for (const auto& method : methods) print_row("mean", method, summaries[method].mean);
  for (const auto& method : methods) print_row("all points", method, summaries[method].pooled);
  if (!without_positives.empty())
    log().warn(
        "{} of {} files have no {} point ({}{}): their MCC is undefined and counts as 0 in the "
        "median and mean, whatever a method predicts; the all-points row pools their counts",
        without_positives.size(), truth_files.size(), edges::to_string(task),
        without_positives.front(), without_positives.size() > 1 ? ", ..." : "");
  if (!options.report.empty()) {
    io::write_json(options.report, {{"command", command_line()},
                                    {"task", options.task},
                                    {"models", options.models},
                                    {"baseline",
                                     {{"method", "covariance analysis (Bazazian et al. 2015)"},
                                      {"k", options.baseline.k},
                                      {"threshold", options.baseline.threshold},
                                      {"enabled", !options.no_baseline}}},
                                    {"angle_gap_baseline",
                                     {{"method",
                                       "largest angular gap of the radius neighbours around the "
                                       "PCA normal (PCL BoundaryEstimation / Open3D rule)"},
                                      {"k", options.angle_gap.k},
                                      {"radius_spacings", options.angle_gap.radius_spacings},
                                      {"radius", options.angle_gap.radius},
                                      {"angle_threshold_rad", options.angle_gap.angle_threshold},
                                      {"enabled", run_angle_gap}}},
                                    {"files", files_json},
                                    {"files_without_positives", without_positives},
                                    {"summary", summary_json}});
    fmt::print("report -> {}\n", options.report);
  }
}

}  // namespace

void register_edges_eval(CLI::App& edges) {
  auto options = std::make_shared<EvalOptions>();
  CLI::App* command = edges.add_subcommand(
      "eval",
      "Score edge/boundary classifications against labelled clouds (thesis §5.5.2):\n"
      "Precision, Recall, MCC, F1, Accuracy, IoU per file, then median and mean.\n"
      "Methods: each --model (classified here), --pred files (e.g. from 'edges classify'\n"
      "or another tool; read from label/scalar_label), and the covariance-analysis baseline\n"
      "CA (surface variation > threshold), printed beside glint unless --no-baseline,\n"
      "and for --task boundary or edge the angle-gap boundary baseline (PCL's\n"
      "BoundaryEstimation rule on PCA normals: boundary where the neighbours within\n"
      "--ag-radius-spacings local spacings leave an angular gap > --ag-threshold).\n"
      "With neither --model nor --pred the shipped 3-class model is evaluated.\n"
      "Example: glint edges eval ../shared/data/pointclouds/default-eval \\\n"
      "           --model models/bounded-3c.json --model models/bounded-2c.json");
  command
      ->add_option("ground_truth", options->ground_truth,
                   "Labelled clouds or folders (label: 0 non-edge, 1 sharp, 2 boundary)")
      ->required();
  command->add_option("--model", options->models, "Model JSON to evaluate (repeatable)");
  command->add_option("--pred", options->predictions,
                      "Predicted labels: one file per ground-truth file, or a folder of files "
                      "with the same names");
  command
      ->add_option("--task", options->task,
                   "sharp: sharp vs rest (Table 5.1); boundary: boundary vs rest; "
                   "edge: sharp or boundary vs non-edge")
      ->capture_default_str();
  command->add_option("--ca-k", options->baseline.k, "CA neighbourhood size")
      ->capture_default_str();
  command
      ->add_option("--ca-threshold", options->baseline.threshold,
                   "CA surface-variation threshold (0.025: thesis, tuned on Default)")
      ->capture_default_str();
  command
      ->add_option("--ag-k", options->angle_gap.k,
                   "Angle-gap: neighbours for the PCA normal and the local spacing")
      ->capture_default_str();
  command
      ->add_option("--ag-radius-spacings", options->angle_gap.radius_spacings,
                   "Angle-gap: search radius in local point spacings (spacing = k-th neighbour "
                   "distance x sqrt(pi/k))")
      ->capture_default_str();
  command
      ->add_option("--ag-radius", options->angle_gap.radius,
                   "Angle-gap: fixed search radius in cloud units instead (0 = adaptive)")
      ->capture_default_str();
  command
      ->add_option("--ag-threshold", options->angle_gap.angle_threshold,
                   "Angle-gap: boundary when the largest gap exceeds this, radians (pi/2: the "
                   "PCL and Open3D default)")
      ->capture_default_str();
  command->add_flag("--no-baseline", options->no_baseline, "Skip the CA and angle-gap baselines");
  command->add_option("--report", options->report, "Write all scores as JSON")->check(kOutputFile);
  command->callback([options] { run_eval(*options); });
}

}  // namespace glint::app
