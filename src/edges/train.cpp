#include "edges/train.h"

#include <fmt/format.h>
#include <tbb/global_control.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/best_parameters.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/timer.h"

namespace glint::edges {
namespace {

// The network of edges/model.h as torch modules; forward() returns the logits.
class BoundedNetImpl : public torch::nn::Module {
 public:
  BoundedNetImpl(const ModelConfig& config, double dropout) : config_(config) {
    const auto columns = static_cast<std::int64_t>(config.input_columns());
    input_mean_ = register_buffer("input_mean", torch::zeros({columns}));
    input_std_ = register_buffer("input_std", torch::ones({columns}));
    const std::vector<DenseLayer> shapes = make_layers(config);
    for (std::size_t l = 0; l < shapes.size(); ++l)
      linears_.push_back(register_module(fmt::format("layer{}", l),
                                         torch::nn::Linear(shapes[l].inputs, shapes[l].outputs)));
    dropout_ = register_module("dropout", torch::nn::Dropout(dropout));
  }

  torch::Tensor forward(torch::Tensor x) {
    const double slope = config_.leaky_slope;
    auto leaky = [slope](const torch::Tensor& t) { return torch::leaky_relu(t, slope); };
    x = (x - input_mean_) / input_std_;
    // Fusion tree: node j of a level reads vectors 2j and 2j+1 (adjacent columns).
    std::size_t layer = 0;
    std::int64_t width = config_.features_per_scale();
    for (int vectors = static_cast<int>(config_.scales.size()); vectors > 2;
         vectors /= 2, width = config_.fusion_width) {
      std::vector<torch::Tensor> fused;
      for (int node = 0; node < vectors / 2; ++node)
        fused.push_back(
            leaky(linears_[layer++]->forward(x.narrow(1, 2 * node * width, 2 * width))));
      x = torch::cat(fused, 1);
    }
    for (int h = 0; h < config_.hidden_layers; ++h)
      x = dropout_->forward(leaky(linears_[layer++]->forward(x)));
    return linears_[layer]->forward(x);
  }

  void set_standardisation(const std::vector<float>& mean, const std::vector<float>& std) {
    torch::NoGradGuard no_grad;
    input_mean_.copy_(torch::tensor(mean));
    input_std_.copy_(torch::tensor(std));
  }

  void import_weights(const Model& model) {
    torch::NoGradGuard no_grad;
    set_standardisation(model.input_mean, model.input_std);
    for (std::size_t l = 0; l < linears_.size(); ++l) {
      const DenseLayer& layer = model.layers[l];
      linears_[l]->weight.copy_(torch::tensor(layer.weights).view({layer.outputs, layer.inputs}));
      linears_[l]->bias.copy_(torch::tensor(layer.bias));
    }
  }

  // Adds `offset` to the bias of output class 0 (non-edge).
  void shift_non_edge_logit(double offset) {
    torch::NoGradGuard no_grad;
    linears_.back()->bias[0] += offset;
  }

  void export_weights(Model& model) const {
    auto copy_out = [](const torch::Tensor& tensor, std::vector<float>& values) {
      const torch::Tensor contiguous = tensor.detach().contiguous();
      const float* data = contiguous.data_ptr<float>();
      values.assign(data, data + contiguous.numel());
    };
    copy_out(input_mean_, model.input_mean);
    copy_out(input_std_, model.input_std);
    for (std::size_t l = 0; l < linears_.size(); ++l) {
      copy_out(linears_[l]->weight, model.layers[l].weights);
      copy_out(linears_[l]->bias, model.layers[l].bias);
    }
  }

 private:
  ModelConfig config_;
  torch::Tensor input_mean_, input_std_;
  std::vector<torch::nn::Linear> linears_;
  torch::nn::Dropout dropout_{nullptr};
};
TORCH_MODULE(BoundedNet);

// Focal loss (Lin et al. 2017): mean of -alpha_t (1 - p_t)^gamma log p_t. alpha may be undefined.
torch::Tensor focal_loss(const torch::Tensor& logits, const torch::Tensor& targets, double gamma,
                         const torch::Tensor& alpha) {
  const torch::Tensor log_p_t =
      torch::log_softmax(logits, 1).gather(1, targets.unsqueeze(1)).squeeze(1);
  torch::Tensor loss = -log_p_t;
  if (gamma != 0.0) loss = loss * torch::pow(1.0 - log_p_t.exp(), gamma);
  if (alpha.defined()) loss = loss * alpha.index_select(0, targets);
  return loss.mean();
}

// A view of the feature values as a points x columns tensor (no copy; never written to).
torch::Tensor feature_tensor(const FeatureMatrix& features) {
  return torch::from_blob(
      const_cast<float*>(features.values.data()),
      {static_cast<std::int64_t>(features.points), static_cast<std::int64_t>(features.row_size())},
      torch::kFloat32);
}

torch::Tensor index_tensor(const std::vector<std::int64_t>& indices) {
  return torch::from_blob(const_cast<std::int64_t*>(indices.data()),
                          {static_cast<std::int64_t>(indices.size())}, torch::kInt64);
}

void check_params(const TrainParams& params, int classes) {
  const std::string where = "training parameters";
  if (params.iterations < 0) throw Error(where, "iterations", "must be >= 0");
  if (params.batch_size < 1) throw Error(where, "batch_size", "must be >= 1");
  if (!(params.learning_rate > 0.0)) throw Error(where, "learning_rate", "must be > 0");
  if (!(params.focal_gamma >= 0.0)) throw Error(where, "focal_gamma", "must be >= 0");
  if (!(params.dropout >= 0.0 && params.dropout < 1.0))
    throw Error(where, "dropout", "must be in [0, 1)");
  if (!(params.validation_fraction >= 0.0 && params.validation_fraction < 1.0))
    throw Error(where, "validation_fraction", "must be in [0, 1)");
  if (params.log_every < 1) throw Error(where, "log_every", "must be >= 1");
  if (!params.class_weights.empty()) {
    if (static_cast<int>(params.class_weights.size()) != classes)
      throw Error(where, "class_weights",
                  fmt::format("need one weight per class ({}), got {}", classes,
                              params.class_weights.size()));
    for (double w : params.class_weights)
      if (!(w > 0.0 && std::isfinite(w)))
        throw Error(where, "class_weights", "weights must be finite and > 0");
  }
}

// Training and validation points per class, the validation part a stratified random sample.
struct Split {
  std::vector<std::vector<std::int64_t>> training;  // per class
  std::vector<std::int64_t> training_all;
  std::vector<std::int64_t> validation;
};

Split split_points(const std::vector<std::uint8_t>& labels, int classes, double fraction,
                   std::mt19937_64& rng) {
  std::vector<std::vector<std::int64_t>> per_class(classes);
  for (std::size_t i = 0; i < labels.size(); ++i)
    per_class[labels[i]].push_back(static_cast<std::int64_t>(i));
  Split split;
  split.training.resize(classes);
  for (int c = 0; c < classes; ++c) {
    std::vector<std::int64_t>& points = per_class[c];
    std::shuffle(points.begin(), points.end(), rng);
    // At least one validation point per present class, at least one training point kept.
    std::size_t held_out = 0;
    if (fraction > 0.0 && points.size() >= 2)
      held_out =
          std::clamp<std::size_t>(std::llround(fraction * points.size()), 1, points.size() - 1);
    split.validation.insert(split.validation.end(), points.begin(), points.begin() + held_out);
    split.training[c].assign(points.begin() + held_out, points.end());
    std::sort(split.training[c].begin(), split.training[c].end());
    split.training_all.insert(split.training_all.end(), split.training[c].begin(),
                              split.training[c].end());
  }
  std::sort(split.training_all.begin(), split.training_all.end());
  std::sort(split.validation.begin(), split.validation.end());
  return split;
}

// Per-column mean and standard deviation (floored) of the given points.
void standardisation(const FeatureMatrix& features, const std::vector<std::int64_t>& points,
                     std::vector<float>& mean, std::vector<float>& std) {
  const std::size_t columns = features.row_size();
  std::vector<double> sum(columns, 0.0), squares(columns, 0.0);
  for (std::int64_t p : points) {
    const float* row = features.row(static_cast<std::size_t>(p));
    for (std::size_t c = 0; c < columns; ++c) sum[c] += row[c];
  }
  const double count = static_cast<double>(points.size());
  for (std::size_t c = 0; c < columns; ++c) sum[c] /= count;
  for (std::int64_t p : points) {
    const float* row = features.row(static_cast<std::size_t>(p));
    for (std::size_t c = 0; c < columns; ++c) squares[c] += (row[c] - sum[c]) * (row[c] - sum[c]);
  }
  mean.resize(columns);
  std.resize(columns);
  for (std::size_t c = 0; c < columns; ++c) {
    mean[c] = static_cast<float>(sum[c]);
    std[c] = std::max(Model::kMinInputStd, static_cast<float>(std::sqrt(squares[c] / count)));
  }
}

struct Evaluation {
  double loss = 0.0;
  double accuracy = 0.0;
  std::vector<double> recall;  // per class; NaN for classes without points
};

// The net's logits in evaluation mode (dropout off), without gradients.
torch::Tensor evaluation_logits(BoundedNet& net, const torch::Tensor& features) {
  torch::NoGradGuard no_grad;
  net->eval();
  torch::Tensor logits = net->forward(features);
  net->train();
  return logits;
}

Evaluation evaluate(const torch::Tensor& logits, const torch::Tensor& targets, int classes,
                    double gamma, const torch::Tensor& alpha) {
  Evaluation result;
  result.loss = focal_loss(logits, targets, gamma, alpha).item<double>();
  const torch::Tensor correct = logits.argmax(1).eq(targets);
  result.accuracy = correct.to(torch::kFloat64).mean().item<double>();
  for (int c = 0; c < classes; ++c) {
    const torch::Tensor of_class = targets.eq(c);
    const double count = of_class.sum().item<double>();
    result.recall.push_back(count > 0 ? (correct & of_class).sum().item<double>() / count
                                      : std::nan(""));
  }
  return result;
}

// Mean F1 over the edge classes (1..C-1) present among the targets.
double mean_edge_f1(const torch::Tensor& predicted, const torch::Tensor& targets, int classes) {
  double sum = 0.0;
  int present = 0;
  for (int c = 1; c < classes; ++c) {
    const torch::Tensor is_class = targets.eq(c), said_class = predicted.eq(c);
    const double positives = is_class.sum().item<double>();
    if (positives == 0) continue;
    const double hits = (is_class & said_class).sum().item<double>();
    sum += 2.0 * hits / (positives + said_class.sum().item<double>());
    ++present;
  }
  return present ? sum / present : 0.0;
}

// The offset for the non-edge logit that maximises the mean edge F1 on the given points, from a
// grid over [-4, 8] (ties: the smallest magnitude).
double tune_non_edge_offset(const torch::Tensor& logits, const torch::Tensor& targets, int classes,
                            nlohmann::json& record) {
  double best_offset = 0.0, best_f1 = -1.0, f1_at_zero = 0.0;
  for (int step = -40; step <= 80; ++step) {
    const double offset = 0.1 * step;
    torch::Tensor shifted = logits.clone();
    shifted.select(1, 0) += offset;
    const double f1 = mean_edge_f1(shifted.argmax(1), targets, classes);
    if (step == 0) f1_at_zero = f1;
    if (f1 > best_f1 + 1e-12 ||
        (std::abs(f1 - best_f1) <= 1e-12 && std::abs(offset) < std::abs(best_offset))) {
      best_f1 = f1;
      best_offset = offset;
    }
  }
  record = {{"non_edge_logit_offset", best_offset},
            {"validation_edge_f1", best_f1},
            {"validation_edge_f1_without_offset", f1_at_zero}};
  return best_offset;
}

nlohmann::json recall_json(const std::vector<double>& recall) {
  nlohmann::json array = nlohmann::json::array();
  for (double r : recall)
    array.push_back(std::isnan(r) ? nlohmann::json(nullptr) : nlohmann::json(r));
  return array;
}

}  // namespace

Model train_model(const TrainingSet& data, const ModelConfig& config, const TrainParams& params) {
  Model model(config);
  model.check_features(data.features);
  check_params(params, config.classes);
  if (data.features.points == 0) throw Error("training data", "", "no points");
  if (data.labels.size() != data.features.points)
    throw Error("training data", "labels",
                fmt::format("{} labels for {} points", data.labels.size(), data.features.points));
  for (std::size_t i = 0; i < data.labels.size(); ++i)
    if (data.labels[i] >= config.classes)
      throw Error(
          "training data", fmt::format("label of point {}", i),
          fmt::format("{} is not a class of a {}-class model", data.labels[i], config.classes));

  const Stopwatch watch;
  const auto threads = static_cast<int>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  torch::set_num_threads(threads);
  torch::manual_seed(params.seed);
  std::mt19937_64 rng(params.seed);

  const Split split = split_points(data.labels, config.classes, params.validation_fraction, rng);
  standardisation(data.features, split.training_all, model.input_mean, model.input_std);

  BoundedNet net(config, params.dropout);
  net->set_standardisation(model.input_mean, model.input_std);
  net->train();
  torch::optim::Adam optimiser(
      net->parameters(),
      torch::optim::AdamOptions(params.learning_rate).betas(std::make_tuple(0.9, 0.999)));

  const torch::Tensor features = feature_tensor(data.features);
  const torch::Tensor labels =
      torch::tensor(std::vector<std::int64_t>(data.labels.begin(), data.labels.end()));
  const torch::Tensor alpha = params.class_weights.empty()
                                  ? torch::Tensor()
                                  : torch::tensor(params.class_weights).to(torch::kFloat32);
  // The validation points never change: select them once.
  const torch::Tensor validation_index = index_tensor(split.validation);
  const torch::Tensor validation_features = features.index_select(0, validation_index);
  const torch::Tensor validation_labels = labels.index_select(0, validation_index);

  // Batch sampling: uniform over all training points, or class by class in turn.
  std::vector<int> present_classes;
  std::vector<std::uniform_int_distribution<std::size_t>> pick_in_class;
  for (int c = 0; c < config.classes; ++c) {
    pick_in_class.emplace_back(0, std::max<std::size_t>(split.training[c].size(), 1) - 1);
    if (!split.training[c].empty()) present_classes.push_back(c);
  }
  std::uniform_int_distribution<std::size_t> pick_any(0, split.training_all.size() - 1);
  std::vector<std::int64_t> batch(static_cast<std::size_t>(params.batch_size));
  auto sample_batch = [&] {
    for (std::size_t i = 0; i < batch.size(); ++i) {
      if (params.balance_classes) {
        const int c = present_classes[i % present_classes.size()];
        batch[i] = split.training[c][pick_in_class[c](rng)];
      } else {
        batch[i] = split.training_all[pick_any(rng)];
      }
    }
  };

  nlohmann::json history = nlohmann::json::array();
  BestParameters<torch::Tensor> best_parameters;
  Evaluation best;
  double window_loss = 0.0, last_train_loss = std::nan("");
  int window_size = 0;

  ProgressBar progress("train", static_cast<std::size_t>(params.iterations));
  for (int iteration = 1; iteration <= params.iterations; ++iteration) {
    sample_batch();
    const torch::Tensor index = index_tensor(batch);
    optimiser.zero_grad();
    const torch::Tensor loss = focal_loss(net->forward(features.index_select(0, index)),
                                          labels.index_select(0, index), params.focal_gamma, alpha);
    loss.backward();
    optimiser.step();
    window_loss += loss.item<double>();
    ++window_size;
    progress.advance();

    if (iteration % params.log_every != 0 && iteration != params.iterations) continue;
    last_train_loss = window_loss / window_size;
    window_loss = 0.0;
    window_size = 0;
    nlohmann::json entry{{"iteration", iteration}, {"train_loss", last_train_loss}};
    if (split.validation.empty()) {
      log().info("iteration {}/{}: training loss {:.5f}", iteration, params.iterations,
                 last_train_loss);
    } else {
      const Evaluation validation =
          evaluate(evaluation_logits(net, validation_features), validation_labels, config.classes,
                   params.focal_gamma, alpha);
      entry["validation_loss"] = validation.loss;
      entry["validation_accuracy"] = validation.accuracy;
      entry["validation_recall"] = recall_json(validation.recall);
      log().info(
          "iteration {}/{}: training loss {:.5f}, validation loss {:.5f}, accuracy "
          "{:.4f}, recall per class {}",
          iteration, params.iterations, last_train_loss, validation.loss, validation.accuracy,
          recall_json(validation.recall).dump());
      if (best_parameters.offer(net->parameters(), validation.loss, iteration)) best = validation;
    }
    history.push_back(entry);
  }
  progress.finish();

  if (best_parameters.restore(net->parameters()))
    log().info("kept the weights of iteration {} (lowest validation loss {:.5f})",
               best_parameters.step(), best.loss);
  nlohmann::json threshold = nullptr;
  if (params.tune_threshold && !split.validation.empty()) {
    const double offset = tune_non_edge_offset(evaluation_logits(net, validation_features),
                                               validation_labels, config.classes, threshold);
    net->shift_non_edge_logit(offset);
    log().info("non-edge logit offset {:+.1f}: mean edge F1 on validation {:.4f} (without: {:.4f})",
               offset, threshold["validation_edge_f1"].get<double>(),
               threshold["validation_edge_f1_without_offset"].get<double>());
  }
  net->export_weights(model);

  std::vector<std::size_t> training_counts, validation_counts(config.classes, 0);
  for (const auto& points : split.training) training_counts.push_back(points.size());
  for (std::int64_t p : split.validation) ++validation_counts[data.labels[p]];
  nlohmann::json final_losses{{"train_loss", last_train_loss}};
  if (best_parameters.step() > 0)
    final_losses.update({{"best_iteration", best_parameters.step()},
                         {"validation_loss", best.loss},
                         {"validation_accuracy", best.accuracy},
                         {"validation_recall", recall_json(best.recall)}});
  model.training_info = {{"iterations", params.iterations},
                         {"batch_size", params.batch_size},
                         {"learning_rate", params.learning_rate},
                         {"optimiser", "Adam(beta1 0.9, beta2 0.999)"},
                         {"loss", "focal"},
                         {"focal_gamma", params.focal_gamma},
                         {"class_weights", params.class_weights},
                         {"dropout", params.dropout},
                         {"seed", params.seed},
                         {"balance_classes", params.balance_classes},
                         {"threshold_tuning", threshold},
                         {"validation_fraction", params.validation_fraction},
                         {"threads", threads},
                         {"training_points_per_class", training_counts},
                         {"validation_points_per_class", validation_counts},
                         {"history", history},
                         {"final", final_losses},
                         {"seconds", watch.elapsed_s()}};
  return model;
}

std::vector<float> torch_predict(const Model& model, const FeatureMatrix& features) {
  model.check();
  model.check_features(features);
  BoundedNet net(model.config, 0.0);
  net->import_weights(model);
  net->eval();
  torch::NoGradGuard no_grad;
  const torch::Tensor probabilities =
      torch::softmax(net->forward(feature_tensor(features)), 1).contiguous();
  const float* data = probabilities.data_ptr<float>();
  return {data, data + probabilities.numel()};
}

}  // namespace glint::edges
