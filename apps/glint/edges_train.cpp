// glint edges train: trains a BoundED network on labelled point clouds and writes the model file.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/timer.h"
#include "edges/features.h"
#include "edges/train_plugin.h"
#include "io/json_report.h"
#include "io/point_cloud_io.h"

namespace glint::app {
namespace {

struct TrainOptions {
  std::vector<std::string> inputs;
  std::string output;
  std::vector<std::string> exclude;
  std::string report;
  std::string notes;
  edges::ModelConfig config;
  edges::TrainParams params;
};

// Trains in the plugin module (see edges/train_plugin.h), found by core/resources.h.
edges::Model train_in_plugin(const edges::TrainingSet& set, const edges::ModelConfig& config,
                             const edges::TrainParams& params) {
  const auto entry = reinterpret_cast<edges::TrainPluginEntry>(
      plugin_entry(edges::kTrainPlugin, edges::kTrainPluginEntry));
  edges::Model model;
  edges::TrainPluginCall call;
  call.data = &set;
  call.config = &config;
  call.params = &params;
  call.result = &model;
  if (entry(&call) != 0) call.failure.rethrow();
  return model;
}

bool name_matches_any(const std::string& file, const std::vector<std::string>& patterns) {
  const std::string name = std::filesystem::path(file).filename().string();
  return std::any_of(patterns.begin(), patterns.end(), [&](const std::string& pattern) {
    return name.find(pattern) != std::string::npos;
  });
}

// Reads one labelled cloud, appends its features and (mapped) labels to the set and returns
// its provenance entry for the model file.
nlohmann::json add_cloud(const std::string& file, const edges::ModelConfig& config,
                         edges::TrainingSet& set, StageTimings& timings) {
  PointCloud cloud;
  std::optional<std::vector<std::uint8_t>> labels;
  {
    ScopedStage stage(timings, "read");
    cloud = io::read_point_cloud(file);
    labels = io::read_labels(cloud);
  }
  if (!labels)
    throw Error(file, "",
                "has no point labels: training needs labelled clouds (0 non-edge, "
                "1 sharp edge, 2 boundary)");
  std::size_t counts[3] = {0, 0, 0};
  for (std::size_t i = 0; i < labels->size(); ++i) {
    const std::uint8_t label = (*labels)[i];
    if (label > 2)
      throw Error(file, fmt::format("point {}", i),
                  fmt::format("label {} is none of 0 non-edge, 1 sharp edge, 2 boundary", label));
    ++counts[label];
  }
  edges::FeatureMatrix features;
  {
    ScopedStage stage(timings, "features");
    features = edges::compute_features(cloud, config.feature_params());
  }
  log().info("{}: {} points ({} non-edge, {} sharp, {} boundary)", file, cloud.size(), counts[0],
             counts[1], counts[2]);

  if (set.features.points == 0) {
    set.features.scales = features.scales;
    set.features.per_scale = features.per_scale;
  }
  set.features.points += features.points;
  set.features.values.insert(set.features.values.end(), features.values.begin(),
                             features.values.end());
  for (std::uint8_t label : *labels)  // a 2-class model has no boundary class: boundary -> non-edge
    set.labels.push_back(config.classes == 2 && label == 2 ? 0 : label);

  return {
      {"file", file},
      {"points", cloud.size()},
      {"labels", {{"non-edge", counts[0]}, {"sharp-edge", counts[1]}, {"boundary", counts[2]}}}};
}

void run_train(const TrainOptions& options) {
  const Stopwatch total;
  edges::check_config(options.config);
  std::vector<std::string> files, excluded;
  for (const std::string& file : expand_point_cloud_inputs(options.inputs))
    (name_matches_any(file, options.exclude) ? excluded : files).push_back(file);
  for (const std::string& file : excluded) log().info("excluded {}", file);
  if (files.empty()) throw Error("", "DATA", "no training file left after --exclude");

  StageTimings timings;
  edges::TrainingSet set;
  nlohmann::json file_entries = nlohmann::json::array();
  for (const std::string& file : files)
    file_entries.push_back(add_cloud(file, options.config, set, timings));

  log().info("training on {} points from {} files; network with {} trainable parameters",
             set.features.points, files.size(), edges::Model(options.config).parameter_count());
  edges::Model model;
  {
    ScopedStage stage(timings, "training");
    model = train_in_plugin(set, options.config, options.params);
  }
  model.training_info["command_line"] = command_line();
  model.training_info["files"] = file_entries;
  model.training_info["excluded_files"] = excluded;
  model.training_info["exclude_patterns"] = options.exclude;
  if (!options.notes.empty()) model.training_info["notes"] = options.notes;
  model.save(options.output);
  log().info("wrote {} ({} parameters)", options.output, model.parameter_count());

  if (!options.report.empty()) {
    timings.add("total", total.elapsed_ms());
    io::write_json(options.report, {{"command", "edges train"},
                                    {"command_line", command_line()},
                                    {"inputs", files},
                                    {"excluded", excluded},
                                    {"output", options.output},
                                    {"parameter_count", model.parameter_count()},
                                    {"training", model.training_info},
                                    {"timings_ms", timings.to_json()}});
  }
}

}  // namespace

void register_edges_train(CLI::App& edges) {
  auto options = std::make_shared<TrainOptions>();
  const edges::TrainParams defaults;
  CLI::App* command = edges.add_subcommand(
      "train", "Train a BoundED network on labelled point clouds and write a model file (JSON)");
  command->footer(fmt::format(
      "DATA: point-cloud files or folders (searched recursively for .ply .xyz .pts .txt .csv "
      ".pcd)\n"
      "whose points carry labels 0 non-edge, 1 sharp edge, 2 boundary (e.g. the output of\n"
      "'glint edges synth' or shared/data/pointclouds/bazazian). Every file must be labelled.\n"
      "Features are computed with the model's --scales; the model file records them, the\n"
      "command line, the seed, the files used and their label counts.\n"
      "Training (thesis §5.4.3-5.4.4): focal loss gamma {}, Adam lr {}, batches of {} points\n"
      "drawn at random, {} iterations (the thesis: 3000 on Default, 8000 on ABC); {} % of each\n"
      "class is held out for validation and the weights with the lowest validation loss are kept.\n"
      "Example:\n"
      "  glint edges train data/train/ --exclude eval_ -o models/my-3c.json --report train.json",
      defaults.focal_gamma, defaults.learning_rate, defaults.batch_size, defaults.iterations,
      100 * defaults.validation_fraction));
  command->add_option("DATA", options->inputs, "Labelled point-cloud files or folders")->required();
  command->add_option("-o,--output", options->output, "Model file to write (.json)")
      ->required()
      ->check(kOutputFile);
  command
      ->add_option("--classes", options->config.classes,
                   "3: non-edge/sharp/boundary; 2: non-edge/sharp (boundary counts as non-edge)")
      ->check(CLI::IsMember({2, 3}))
      ->capture_default_str();
  command
      ->add_option("--scales", options->config.scales,
                   "Neighbourhood sizes k, largest first; a power of two of them")
      ->delimiter(',')
      ->capture_default_str();
  command->add_flag("--angular-gap", options->config.angular_gap,
                    "Add a thirteenth input per scale: the largest empty sector of the neighbours "
                    "around the normal (PCL's boundary rule, graded; the shipped 3-class model "
                    "has it)");
  command->add_flag("--area-weights", options->config.area_weights,
                    "Weigh each neighbour by the surface it stands for (its squared distance to "
                    "its 8th nearest point, relative to the query's, clamped to [1/16, 16]): "
                    "features that follow the surface rather than the sampling density, e.g. "
                    "the mesh vertices of CAD tessellations (the shipped 2-class model has it)");
  command
      ->add_option("--exclude", options->exclude,
                   "Skip files whose name contains PATTERN; repeat the flag for more patterns "
                   "(--exclude a --exclude b), e.g. to keep evaluation twins out")
      ->allow_extra_args(false);
  command->add_option("--iterations", options->params.iterations, "Training iterations")
      ->check(kNonNegative)
      ->capture_default_str();
  command
      ->add_option("--dropout", options->params.dropout,
                   "Dropout probability in the classification layers (the thesis: 0.5)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  command->add_option("--batch", options->params.batch_size, "Points per batch")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--lr", options->params.learning_rate, "Adam learning rate")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--gamma", options->params.focal_gamma, "Focal-loss gamma (0 = cross-entropy)")
      ->check(kNonNegative)
      ->capture_default_str();
  command
      ->add_option("--class-weights", options->params.class_weights,
                   "Focal-loss alpha per class, comma-separated (default: none)")
      ->delimiter(',');
  command
      ->add_option("--validation", options->params.validation_fraction,
                   "Fraction of each class held out for validation (0 = none, keep the last "
                   "weights)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  command
      ->add_option("--log-every", options->params.log_every,
                   "Iterations between validation evaluations")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--seed", options->params.seed,
                   "Seed of the initialisation, dropout, batches and validation split")
      ->capture_default_str();
  command->add_flag("--balance", options->params.balance_classes,
                    "Draw every batch with the classes in equal numbers (default off: uniform "
                    "batches, the focal loss copes with the imbalance as in the thesis)");
  command->add_flag("!--no-threshold-tuning", options->params.tune_threshold,
                    "Keep the raw argmax decision (default: after training, shift the non-edge "
                    "logit to maximise the mean edge-class F1 on the validation points)");
  command->add_option("--notes", options->notes, "Free text stored in the model's training record");
  command->add_option("--report", options->report, "Write a JSON report (inputs, timings, losses)")
      ->check(kOutputFile);
  command->callback([options] { run_train(*options); });
}

}  // namespace glint::app
