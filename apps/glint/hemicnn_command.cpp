// glint hemicnn train | predict: trains the HemiCNN on a hemi-image dataset (glint hemicnn
// dataset) and evaluates a model on a dataset's validation split. The `hemicnn` parent
// command is registered in hemicnn_commands.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <numeric>
#include <random>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/json_report.h"
#include "reflectance/hemi_dataset.h"
#include "reflectance/hemicnn.h"
#include "reflectance/hemicnn_train_plugin.h"
#include "render/perceptual.h"

namespace glint::app {
namespace {

struct TrainOptions {
  std::string dataset;
  std::string output;
  std::string report;
  reflectance::HemiCnnTrainParams params;
};

struct PredictOptions {
  std::string dataset;
  std::string model;
  std::string report;
  double validation_fraction = 0.1;
  int sets = 8;
  std::uint64_t seed = 1;
};

// Trains in the plugin module (see reflectance/hemicnn_train_plugin.h), found by
// core/resources.h.
reflectance::HemiCnn train_in_plugin(const reflectance::HemiDataset& data,
                                     const reflectance::HemiCnnConfig& config,
                                     const reflectance::HemiCnnTrainParams& params) {
  const auto entry = reinterpret_cast<reflectance::HemiCnnPluginEntry>(
      plugin_entry(reflectance::kHemiCnnPlugin, reflectance::kHemiCnnPluginEntry));
  reflectance::HemiCnn model;
  reflectance::HemiCnnPluginCall call;
  call.data = &data;
  call.config = &config;
  call.params = &params;
  call.result = &model;
  if (entry(&call) != 0) call.failure.rethrow();
  return model;
}

reflectance::HemiDataset read_dataset(const std::string& folder, StageTimings& timings) {
  ScopedStage stage(timings, "read");
  reflectance::HemiDataset data = reflectance::read_hemi_dataset(folder);
  std::size_t images = 0;
  for (const auto& sequence : data.sequences) images += sequence.images;
  log().info("{}: {} sequences, {} hemi-images of {}x{} ({}, {})", folder, data.sequences.size(),
             images, data.size, data.size, reflectance::hemi_projection_name(data.projection),
             reflectance::hemi_input_name(data.input));
  return data;
}

void run_train(const TrainOptions& options) {
  const Stopwatch total;
  StageTimings timings;
  const reflectance::HemiDataset data = read_dataset(options.dataset, timings);
  reflectance::HemiCnnConfig config;
  config.image_size = data.size;  // for the parameter count; training takes it from the data
  log().info("network with {} trainable parameters; {} batches of {} sets of {}",
             reflectance::HemiCnn(config).parameter_count(), options.params.batches,
             options.params.batch_size, options.params.set_size);
  reflectance::HemiCnn model;
  {
    ScopedStage stage(timings, "training");
    model = train_in_plugin(data, config, options.params);
  }
  model.training_info["command_line"] = command_line();
  model.training_info["dataset"] = options.dataset;
  model.save(options.output);
  log().info("wrote {} ({} parameters)", options.output, model.parameter_count());

  if (!options.report.empty()) {
    timings.add("total", total.elapsed_ms());
    io::write_json(options.report, {{"command", "hemicnn train"},
                                    {"command_line", command_line()},
                                    {"dataset", options.dataset},
                                    {"output", options.output},
                                    {"parameter_count", model.parameter_count()},
                                    {"training", model.training_info},
                                    {"timings_ms", timings.to_json()}});
  }
}

// Absolute errors of one prediction against the ground truth, in Ward and perceptual terms.
struct Errors {
  double kd = 0, ks = 0, alpha = 0;  // mean over channels for kd and ks
  double perceptual[reflectance::HemiCnn::kTargets] = {};
  double loss = 0;  // eq. (5) with the paper's weights

  void add(const Errors& other) {
    kd += other.kd;
    ks += other.ks;
    alpha += other.alpha;
    for (int t = 0; t < reflectance::HemiCnn::kTargets; ++t) perceptual[t] += other.perceptual[t];
    loss += other.loss;
  }
  void scale(double factor) {
    kd *= factor;
    ks *= factor;
    alpha *= factor;
    for (double& e : perceptual) e *= factor;
    loss *= factor;
  }
  nlohmann::json to_json() const {
    return {{"kd", kd},
            {"ks", ks},
            {"alpha", alpha},
            {"L", perceptual[0]},
            {"a", perceptual[1]},
            {"b", perceptual[2]},
            {"c", (perceptual[3] + perceptual[4] + perceptual[5]) / 3},
            {"d", perceptual[6]},
            {"loss", loss}};
  }
};

Errors errors_of(const render::PerceptualWard& estimate, const render::PerceptualWard& truth,
                 const render::WardMaterial& truth_material) {
  Errors e;
  const render::WardMaterial material = render::from_perceptual(estimate);
  e.kd = (material.kd - truth_material.kd).cwiseAbs().mean();
  e.ks = (material.ks - truth_material.ks).cwiseAbs().mean();
  e.alpha = std::abs(material.alpha - truth_material.alpha);
  const auto a = reflectance::to_targets(estimate), b = reflectance::to_targets(truth);
  for (int t = 0; t < reflectance::HemiCnn::kTargets; ++t) e.perceptual[t] = std::abs(a[t] - b[t]);
  e.loss = reflectance::hemicnn_loss(estimate, truth);
  return e;
}

void run_predict(const PredictOptions& options) {
  const Stopwatch total;
  StageTimings timings;
  const reflectance::HemiCnn model = reflectance::HemiCnn::load(options.model);
  const reflectance::HemiDataset data = read_dataset(options.dataset, timings);
  if (data.projection != model.projection() || data.input != model.input() ||
      data.size != model.image_size())
    throw Error(options.dataset, "projection",
                fmt::format("holds {} {} {}x{} hemi-images; the model {} was trained on {} {} "
                            "{}x{}",
                            reflectance::hemi_projection_name(data.projection),
                            reflectance::hemi_input_name(data.input), data.size, data.size,
                            options.model, reflectance::hemi_projection_name(model.projection()),
                            reflectance::hemi_input_name(model.input()), model.image_size(),
                            model.image_size()));
  const int sequence_count = static_cast<int>(data.sequences.size());
  const int evaluated =
      std::clamp(static_cast<int>(std::lround(options.validation_fraction * sequence_count)), 1,
                 sequence_count);
  const int set_size = 25;

  std::mt19937_64 rng(options.seed);
  std::vector<int> order;
  std::vector<float> images(set_size * model.image_floats());
  reflectance::HemiCnnScratch scratch;
  Errors mean;
  nlohmann::json per_sequence = nlohmann::json::array();
  double inference_ms = 0;
  ProgressBar progress("predict", static_cast<std::size_t>(evaluated));
  for (int s = sequence_count - evaluated; s < sequence_count; ++s) {
    const reflectance::HemiSequence& sequence = data.sequences[s];
    Errors sequence_errors;
    for (int k = 0; k < options.sets; ++k) {
      order.resize(sequence.images);
      std::iota(order.begin(), order.end(), 0);
      for (int i = 0; i < set_size; ++i) {
        std::swap(order[i], order[std::uniform_int_distribution<int>(i, sequence.images - 1)(rng)]);
        std::copy_n(sequence.image(order[i], data.size), model.image_floats(),
                    images.data() + i * model.image_floats());
      }
      const Stopwatch watch;
      const render::PerceptualWard estimate = model.predict(images.data(), set_size, scratch);
      inference_ms += watch.elapsed_ms();
      sequence_errors.add(errors_of(estimate, sequence.target, sequence.material));
    }
    sequence_errors.scale(1.0 / options.sets);
    mean.add(sequence_errors);
    per_sequence.push_back({{"file", sequence.file},
                            {"source", sequence.source},
                            {"kd", io::vector_json(sequence.material.kd)},
                            {"ks", io::vector_json(sequence.material.ks)},
                            {"alpha", sequence.material.alpha},
                            {"mean_absolute_error", sequence_errors.to_json()}});
    progress.advance();
  }
  progress.finish();
  mean.scale(1.0 / evaluated);
  const double ms_per_set = inference_ms / (double(evaluated) * options.sets);
  timings.add("total", total.elapsed_ms());

  fmt::print(
      "HemiCNN {} ({}, {} parameters) on the last {} of {} sequences of {}, {} sets of {} each:\n"
      "  mean absolute error  kd {:.4f}  ks {:.4f}  alpha {:.4f}\n"
      "  perceptual           L {:.2f}  a {:.2f}  b {:.2f}  c {:.4f}  d {:.4f}\n"
      "  eq. (5) loss (lambda_d 0.1, lambda_l 0.3): {:.5f}\n"
      "  inference {:.3f} ms per set (one thread)\n",
      options.model, reflectance::hemi_projection_name(model.projection()), model.parameter_count(),
      evaluated, sequence_count, options.dataset, options.sets, set_size, mean.kd, mean.ks,
      mean.alpha, mean.perceptual[0], mean.perceptual[1], mean.perceptual[2],
      (mean.perceptual[3] + mean.perceptual[4] + mean.perceptual[5]) / 3, mean.perceptual[6],
      mean.loss, ms_per_set);

  if (!options.report.empty()) {
    io::write_json(options.report,
                   {{"command", "hemicnn predict"},
                    {"command_line", command_line()},
                    {"model", options.model},
                    {"dataset", options.dataset},
                    {"projection", reflectance::hemi_projection_name(model.projection())},
                    {"sequences", sequence_count},
                    {"evaluated_sequences", evaluated},
                    {"sets_per_sequence", options.sets},
                    {"set_size", set_size},
                    {"seed", options.seed},
                    {"mean_absolute_error", mean.to_json()},
                    {"inference_ms_per_set", ms_per_set},
                    {"per_sequence", per_sequence},
                    {"timings_ms", timings.to_json()}});
    fmt::print("report -> {}\n", options.report);
  }
}

}  // namespace

void register_hemicnn_train(CLI::App& hemicnn) {
  auto options = std::make_shared<TrainOptions>();
  const reflectance::HemiCnnTrainParams defaults;
  CLI::App* command = hemicnn.add_subcommand(
      "train", "Train the HemiCNN on a hemi-image dataset and write a model file (JSON)");
  command->footer(fmt::format(
      "DATASET: a folder made by 'glint hemicnn dataset' (index.json + seq_*.npy); its\n"
      "projection (parabolic or orthographic) and input (radiance or reflectance) are stored\n"
      "in the model, and the pipeline makes its hemi-images the same way.\n"
      "Training (paper 1 §3.6, §4.1): each example is 25 random hemi-images of one random\n"
      "training sequence; loss eq. (5) with Lab in units of 100; Adam lr {}, batches of {};\n"
      "the last {} % of the sequences are held out and the weights with the lowest validation\n"
      "loss are kept. The paper trains 150k batches on a GPU; the default {} batches take\n"
      "8-10 minutes on one CPU core (44-55 batches/s measured; see --torch-threads).\n"
      "Examples:\n"
      "  # the modified HemiCNN (paper 1: lambda_d 0.1, lambda_l 0.3, parabolic hemi-images)\n"
      "  glint hemicnn train hemi/parabolic-reflectance -o models/hemicnn.json --report t.json\n"
      "  # the unmodified HemiCNN of Kim et al. (lambda_d = lambda_l = 1, orthographic)\n"
      "  glint hemicnn train hemi/orthographic-reflectance --lambda-d 1 --lambda-l 1 \\\n"
      "    -o models/hemicnn-unmodified.json\n"
      "  # either on radiance hemi-images, paper 1's input (scripts/train-hemicnn.sh)\n"
      "  glint hemicnn train hemi/parabolic -o models/hemicnn-radiance.json",
      defaults.learning_rate, defaults.batch_size, 100 * defaults.validation_fraction,
      defaults.batches));
  command->add_option("DATASET", options->dataset, "Hemi-image dataset folder")->required();
  command->add_option("-o,--output", options->output, "Model file to write (.json)")
      ->required()
      ->check(kOutputFile);
  command
      ->add_option("--lambda-d", options->params.loss.lambda_d,
                   "Weight of the diffuse (Lab) term of eq. (5); Kim et al.: 1")
      ->check(kNonNegative)
      ->capture_default_str();
  command
      ->add_option("--lambda-l", options->params.loss.lambda_l,
                   "Weight of L inside the diffuse term; Kim et al.: 1")
      ->check(kNonNegative)
      ->capture_default_str();
  command->add_option("--batches", options->params.batches, "Training batches")
      ->check(kNonNegative)
      ->capture_default_str();
  command->add_option("--batch-size", options->params.batch_size, "Sets of 25 per batch")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--lr", options->params.learning_rate, "Adam learning rate")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--validation", options->params.validation_fraction,
                   "Fraction of the sequences (the last ones) held out (0 = none, keep the last "
                   "weights)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  command
      ->add_option("--log-every", options->params.log_every,
                   "Batches between validation evaluations")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--torch-threads", options->params.threads,
                   "libtorch threads (1: this small net's tensors are too small to split; 2 "
                   "threads trained 2-10x slower on a 2-core machine)")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--weight-averaging", options->params.weight_averaging,
                   "Decay of an exponential moving average of the weights, which is validated "
                   "and kept in their place (e.g. 0.999; 0 = off)")
      ->check(CLI::Range(0.0, 0.9999999))
      ->capture_default_str();
  command->add_flag("!--no-rotate", options->params.rotate,
                    "No random quarter turns of the sets (default: each set turned by a random "
                    "multiple of 90 degrees)");
  command->add_option("--seed", options->params.seed, "Seed of the initialisation and the sets")
      ->capture_default_str();
  command->add_option("--report", options->report, "Write a JSON report (timings, losses)")
      ->check(kOutputFile);
  command->callback([options] { run_train(*options); });
}

void register_hemicnn_predict(CLI::App& hemicnn) {
  auto options = std::make_shared<PredictOptions>();
  CLI::App* command = hemicnn.add_subcommand(
      "predict",
      "Evaluate a HemiCNN model on a dataset's validation split: mean absolute errors of kd, ks "
      "and alpha");
  command->footer(
      "From each of the last --validation fraction of the sequences (the split 'glint hemicnn\n"
      "train' held out with the same fraction) --sets random sets of 25 hemi-images are drawn;\n"
      "the model's prediction is converted back to Ward parameters (kd, ks, alpha) and compared\n"
      "with the ground truth. The dataset's projection and input must be the model's.\n"
      "Example (modified vs unmodified HemiCNN):\n"
      "  glint hemicnn predict hemi/parabolic-reflectance --model models/hemicnn.json\n"
      "  glint hemicnn predict hemi/orthographic-reflectance \\\n"
      "    --model models/hemicnn-unmodified.json");
  command->add_option("DATASET", options->dataset, "Hemi-image dataset folder")->required();
  command->add_option("--model", options->model, "HemiCNN model file (.json)")->required();
  command
      ->add_option("--validation", options->validation_fraction,
                   "Fraction of the sequences, the last ones, to evaluate (1 = all)")
      ->check(CLI::Range(0.001, 1.0))
      ->capture_default_str();
  command->add_option("--sets", options->sets, "Random sets of 25 per sequence")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the sets")->capture_default_str();
  command->add_option("--report", options->report, "Write the errors (also per sequence) as JSON")
      ->check(kOutputFile);
  command->callback([options] { run_predict(*options); });
}

}  // namespace glint::app
