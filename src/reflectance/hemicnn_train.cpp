#include "reflectance/hemicnn_train.h"

#include <fmt/format.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>

#include "core/best_parameters.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/timer.h"

namespace glint::reflectance {
namespace {

// Images per sequence that the input standardisation looks at.
constexpr int kStandardisationImages = 64;
// Sets per forward pass when evaluating without gradients.
constexpr int kEvaluationChunk = 64;

// The network of reflectance/hemicnn.h as torch modules; forward() takes [sets, count, 3, S, S]
// radiances and returns the de-standardised outputs [sets, 7].
class HemiNetImpl : public torch::nn::Module {
 public:
  explicit HemiNetImpl(const HemiCnnConfig& config) : config_(config) {
    input_mean_ = register_buffer("input_mean", torch::zeros({1, 3, 1, 1}));
    input_std_ = register_buffer("input_std", torch::ones({1, 3, 1, 1}));
    target_mean_ = register_buffer("target_mean", torch::zeros({HemiCnn::kTargets}));
    target_std_ = register_buffer("target_std", torch::ones({HemiCnn::kTargets}));
    for (const HemiCnnLayer& layer : make_layers(config)) {
      if (layer.kernel == 3)
        convs_.push_back(register_module(
            layer.name,
            torch::nn::Conv2d(
                torch::nn::Conv2dOptions(layer.inputs, layer.outputs, 3).stride(2).padding(1))));
      else
        denses_.push_back(
            register_module(layer.name, torch::nn::Linear(layer.inputs, layer.outputs)));
    }
  }

  torch::Tensor forward(const torch::Tensor& images) {
    const std::int64_t sets = images.size(0), count = images.size(1);
    const double slope = config_.leaky_slope;
    torch::Tensor x = images.reshape({sets * count, 3, images.size(3), images.size(4)});
    x = (torch::log1p(x.clamp_min(0.0)) - input_mean_) / input_std_;
    for (torch::nn::Conv2d& conv : convs_) x = torch::leaky_relu(conv->forward(x), slope);
    x = x.permute({0, 2, 3, 1}).flatten(1);  // (y, x, channel), as the plain-C++ inference
    x = torch::leaky_relu(denses_[0]->forward(x), slope);
    x = x.view({sets, count, -1}).mean(1);
    x = torch::leaky_relu(denses_[1]->forward(x), slope);
    return denses_[2]->forward(x) * target_std_ + target_mean_;
  }

  // The fixed input and target standardisations of `model`.
  void import_standardisations(const HemiCnn& model) {
    torch::NoGradGuard no_grad;
    input_mean_.copy_(torch::tensor(std::vector<float>(model.input_mean, model.input_mean + 3))
                          .view({1, 3, 1, 1}));
    input_std_.copy_(
        torch::tensor(std::vector<float>(model.input_std, model.input_std + 3)).view({1, 3, 1, 1}));
    target_mean_.copy_(torch::tensor(
        std::vector<float>(model.target_mean, model.target_mean + HemiCnn::kTargets)));
    target_std_.copy_(
        torch::tensor(std::vector<float>(model.target_std, model.target_std + HemiCnn::kTargets)));
  }

  void import_weights(const HemiCnn& model) {
    torch::NoGradGuard no_grad;
    import_standardisations(model);
    std::size_t conv = 0, dense = 0;
    for (const HemiCnnLayer& layer : model.layers) {
      const torch::Tensor weights = torch::tensor(layer.weights);
      if (layer.kernel == 3) {
        // [ky][kx][in][out] -> [out][in][ky][kx]
        convs_[conv]->weight.copy_(
            weights.view({3, 3, layer.inputs, layer.outputs}).permute({3, 2, 0, 1}));
        convs_[conv++]->bias.copy_(torch::tensor(layer.bias));
      } else {
        denses_[dense]->weight.copy_(weights.view({layer.inputs, layer.outputs}).t());
        denses_[dense++]->bias.copy_(torch::tensor(layer.bias));
      }
    }
  }

  void export_weights(HemiCnn& model) const {
    auto copy_out = [](const torch::Tensor& tensor, float* values) {
      const torch::Tensor contiguous = tensor.detach().contiguous();
      std::copy_n(contiguous.data_ptr<float>(), contiguous.numel(), values);
    };
    copy_out(input_mean_, model.input_mean);
    copy_out(input_std_, model.input_std);
    copy_out(target_mean_, model.target_mean);
    copy_out(target_std_, model.target_std);
    std::size_t conv = 0, dense = 0;
    for (HemiCnnLayer& layer : model.layers) {
      if (layer.kernel == 3) {
        copy_out(convs_[conv]->weight.permute({2, 3, 1, 0}), layer.weights.data());
        copy_out(convs_[conv++]->bias, layer.bias.data());
      } else {
        copy_out(denses_[dense]->weight.t(), layer.weights.data());
        copy_out(denses_[dense++]->bias, layer.bias.data());
      }
    }
  }

 private:
  HemiCnnConfig config_;
  torch::Tensor input_mean_, input_std_, target_mean_, target_std_;
  std::vector<torch::nn::Conv2d> convs_;
  std::vector<torch::nn::Linear> denses_;  // branch, head, output
};
TORCH_MODULE(HemiNet);

void check_params(const HemiCnnTrainParams& params) {
  const std::string where = "HemiCNN training parameters";
  if (params.batches < 0) throw Error(where, "batches", "must be >= 0");
  if (params.batch_size < 1) throw Error(where, "batch_size", "must be >= 1");
  if (params.set_size < 1) throw Error(where, "set_size", "must be >= 1");
  if (!(params.learning_rate > 0.0)) throw Error(where, "learning_rate", "must be > 0");
  if (!(params.loss.lambda_d >= 0.0) || !(params.loss.lambda_l >= 0.0))
    throw Error(where, "lambda_d/lambda_l", "must be >= 0");
  if (!(params.validation_fraction >= 0.0 && params.validation_fraction < 1.0))
    throw Error(where, "validation_fraction", "must be in [0, 1)");
  if (params.validation_sets < 1) throw Error(where, "validation_sets", "must be >= 1");
  if (params.log_every < 1) throw Error(where, "log_every", "must be >= 1");
  if (params.threads < 1) throw Error(where, "threads", "must be >= 1");
  if (!(params.weight_averaging >= 0.0 && params.weight_averaging < 1.0))
    throw Error(where, "weight_averaging", "must be in [0, 1)");
}

// Copies image `source` (3 x size x size) turned by quarter_turns * 90 degrees into `target`.
void copy_turned(const float* source, float* target, int size, int quarter_turns) {
  const int last = size - 1;
  for (int c = 0; c < 3; ++c, source += size * size, target += size * size)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        int sy = y, sx = x;
        switch (quarter_turns) {
          case 1:
            sy = x, sx = last - y;
            break;
          case 2:
            sy = last - y, sx = last - x;
            break;
          case 3:
            sy = last - x, sx = y;
            break;
          default:
            break;
        }
        target[y * size + x] = source[sy * size + sx];
      }
}

// Draws one set: `count` distinct random images of a sequence, all turned alike, written as
// count x 3 x S x S floats.
class SetSampler {
 public:
  SetSampler(const HemiDataset& data, int count) : data_(data), count_(count) {}

  void draw(const HemiSequence& sequence, bool rotate, std::mt19937_64& rng, float* out) {
    order_.resize(sequence.images);
    std::iota(order_.begin(), order_.end(), 0);
    const std::size_t image_floats = 3 * static_cast<std::size_t>(data_.size) * data_.size;
    const int turns = rotate ? std::uniform_int_distribution<int>(0, 3)(rng) : 0;
    for (int k = 0; k < count_; ++k) {  // partial Fisher-Yates: count distinct images
      const int pick = std::uniform_int_distribution<int>(k, sequence.images - 1)(rng);
      std::swap(order_[k], order_[pick]);
      copy_turned(sequence.image(order_[k], data_.size), out + k * image_floats, data_.size, turns);
    }
  }

 private:
  const HemiDataset& data_;
  int count_;
  std::vector<int> order_;
};

torch::Tensor view_sets(std::vector<float>& buffer, std::int64_t sets, std::int64_t count,
                        std::int64_t size) {
  return torch::from_blob(buffer.data(), {sets, count, 3, size, size}, torch::kFloat32);
}

torch::Tensor targets_tensor(const std::vector<const HemiSequence*>& sequences) {
  std::vector<float> values;
  for (const HemiSequence* sequence : sequences) {
    const std::array<float, HemiCnn::kTargets> t = to_targets(sequence->target);
    values.insert(values.end(), t.begin(), t.end());
  }
  return torch::tensor(values).view(
      {static_cast<std::int64_t>(sequences.size()), HemiCnn::kTargets});
}

// Eq. (5) per set, mean over the sets.
torch::Tensor perceptual_loss(const torch::Tensor& outputs, const torch::Tensor& targets,
                              const torch::Tensor& weights) {
  return ((outputs - targets).square() * weights).sum(1).mean();
}

// Mean absolute error per target over the sets: L, a, b (Lab), c (mean of the three channels)
// and d, the terms of eq. (5) one by one.
nlohmann::json target_errors(const torch::Tensor& outputs, const torch::Tensor& targets) {
  const torch::Tensor errors = (outputs - targets).abs().mean(0).contiguous();
  const float* e = errors.data_ptr<float>();
  return {{"L", e[0]}, {"a", e[1]}, {"b", e[2]}, {"c", (e[3] + e[4] + e[5]) / 3}, {"d", e[6]}};
}

void compute_standardisations(const HemiDataset& data, const std::vector<int>& training,
                              HemiCnn& model) {
  double sum[3] = {0, 0, 0}, squares[3] = {0, 0, 0};
  std::size_t values = 0;
  const std::size_t pixels = static_cast<std::size_t>(data.size) * data.size;
  for (int s : training) {
    const HemiSequence& sequence = data.sequences[s];
    const int images = std::min(sequence.images, kStandardisationImages);
    for (int i = 0; i < images; ++i) {
      const float* image = sequence.image(i, data.size);
      for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < pixels; ++p) {
          const double v = std::log1p(std::max(image[c * pixels + p], 0.0f));
          sum[c] += v;
          squares[c] += v * v;
        }
    }
    values += images * pixels;
  }
  for (int c = 0; c < 3; ++c) {
    const double mean = sum[c] / values;
    model.input_mean[c] = static_cast<float>(mean);
    model.input_std[c] =
        std::max(HemiCnn::kMinStd,
                 static_cast<float>(std::sqrt(std::max(0.0, squares[c] / values - mean * mean))));
  }
  double target_sum[HemiCnn::kTargets] = {}, target_squares[HemiCnn::kTargets] = {};
  for (int s : training) {
    const std::array<float, HemiCnn::kTargets> t = to_targets(data.sequences[s].target);
    for (int k = 0; k < HemiCnn::kTargets; ++k) {
      target_sum[k] += t[k];
      target_squares[k] += double(t[k]) * t[k];
    }
  }
  const double n = static_cast<double>(training.size());
  for (int k = 0; k < HemiCnn::kTargets; ++k) {
    const double mean = target_sum[k] / n;
    model.target_mean[k] = static_cast<float>(mean);
    model.target_std[k] =
        std::max(HemiCnn::kMinStd,
                 static_cast<float>(std::sqrt(std::max(0.0, target_squares[k] / n - mean * mean))));
  }
}

// Fixed validation sets: validation_sets per validation sequence, never rotated.
struct ValidationSets {
  std::vector<float> images;
  std::vector<const HemiSequence*> sequences;  // one per set
  torch::Tensor targets;
};

ValidationSets draw_validation_sets(const HemiDataset& data, const std::vector<int>& validation,
                                    const HemiCnnTrainParams& params) {
  ValidationSets sets;
  std::mt19937_64 rng(params.seed ^ 0x5DEECE66Dull);
  SetSampler sampler(data, params.set_size);
  const std::size_t set_floats =
      static_cast<std::size_t>(params.set_size) * 3 * data.size * data.size;
  for (int s : validation)
    for (int k = 0; k < params.validation_sets; ++k) {
      sets.images.resize(sets.images.size() + set_floats);
      sampler.draw(data.sequences[s], false, rng,
                   sets.images.data() + sets.images.size() - set_floats);
      sets.sequences.push_back(&data.sequences[s]);
    }
  sets.targets = targets_tensor(sets.sequences);
  return sets;
}

// Outputs of the net in chunks of sets, without gradients.
torch::Tensor evaluate_outputs(HemiNet& net, std::vector<float>& images, std::int64_t sets,
                               std::int64_t count, std::int64_t size) {
  torch::NoGradGuard no_grad;
  const torch::Tensor all = view_sets(images, sets, count, size);
  std::vector<torch::Tensor> chunks;
  for (std::int64_t begin = 0; begin < sets; begin += kEvaluationChunk)
    chunks.push_back(
        net->forward(all.narrow(0, begin, std::min<std::int64_t>(kEvaluationChunk, sets - begin))));
  return torch::cat(chunks, 0);
}

// Exponential moving average of a module's parameters (HemiCnnTrainParams::weight_averaging).
class WeightAverage {
 public:
  WeightAverage(const std::vector<torch::Tensor>& parameters, double decay) : decay_(decay) {
    for (const torch::Tensor& p : parameters) average_.push_back(p.detach().clone());
  }

  void update(const std::vector<torch::Tensor>& parameters) {
    torch::NoGradGuard no_grad;
    ++updates_;
    const double decay = std::min(decay_, (1.0 + updates_) / (10.0 + updates_));
    for (std::size_t i = 0; i < average_.size(); ++i)
      average_[i].mul_(decay).add_(parameters[i].detach(), 1.0 - decay);
  }

  // Exchanges the parameters' values with the average's; a second call exchanges them back.
  void exchange(const std::vector<torch::Tensor>& parameters) {
    torch::NoGradGuard no_grad;
    for (std::size_t i = 0; i < average_.size(); ++i) {
      const torch::Tensor own = parameters[i].detach().clone();
      parameters[i].data().copy_(average_[i]);
      average_[i].copy_(own);
    }
  }

 private:
  double decay_;
  long updates_ = 0;
  std::vector<torch::Tensor> average_;
};

}  // namespace

HemiCnn train_hemicnn(const HemiDataset& data, HemiCnnConfig config,
                      const HemiCnnTrainParams& params) {
  check_params(params);
  config.image_size = data.size;
  config.projection = data.projection;
  config.input = data.input;
  HemiCnn model(config);
  const std::string where = data.directory.empty() ? "HemiCNN training data" : data.directory;
  const int sequence_count = static_cast<int>(data.sequences.size());
  for (int s = 0; s < sequence_count; ++s)
    if (data.sequences[s].images < params.set_size ||
        data.sequences[s].values.size() !=
            static_cast<std::size_t>(data.sequences[s].images) * model.image_floats())
      throw Error(where, data.sequences[s].file,
                  fmt::format("{} hemi-images of size {}; a set needs {}", data.sequences[s].images,
                              data.size, params.set_size));

  // Split: the last validation_fraction of the sequences by index.
  int validation_count = 0;
  if (params.validation_fraction > 0.0 && sequence_count >= 2)
    validation_count =
        std::clamp(static_cast<int>(std::lround(params.validation_fraction * sequence_count)), 1,
                   sequence_count - 1);
  std::vector<int> training(sequence_count - validation_count), validation(validation_count);
  std::iota(training.begin(), training.end(), 0);
  std::iota(validation.begin(), validation.end(), sequence_count - validation_count);
  if (training.empty()) throw Error(where, "sequences", "no training sequences");

  const Stopwatch watch;
  const int threads = params.threads;
  torch::set_num_threads(threads);
  torch::manual_seed(params.seed);
  std::mt19937_64 rng(params.seed);

  compute_standardisations(data, training, model);
  HemiNet net(model.config);  // torch's default initialisation
  net->import_standardisations(model);
  net->train();
  torch::optim::Adam optimiser(
      net->parameters(),
      torch::optim::AdamOptions(params.learning_rate).betas(std::make_tuple(0.9, 0.999)));
  const std::array<double, HemiCnn::kTargets> weight_values = loss_weights(params.loss);
  const torch::Tensor weights =
      torch::tensor(std::vector<double>(weight_values.begin(), weight_values.end()))
          .to(torch::kFloat32);

  ValidationSets validation_sets = draw_validation_sets(data, validation, params);
  const auto validation_set_count = static_cast<std::int64_t>(validation_sets.sequences.size());

  const std::size_t set_floats = static_cast<std::size_t>(params.set_size) * model.image_floats();
  std::vector<float> batch_images(set_floats * params.batch_size);
  std::vector<const HemiSequence*> batch_sequences(params.batch_size);
  std::uniform_int_distribution<std::size_t> pick_sequence(0, training.size() - 1);
  SetSampler sampler(data, params.set_size);

  nlohmann::json history = nlohmann::json::array();
  BestParameters<torch::Tensor> best_parameters;
  double window_loss = 0.0, last_train_loss = std::nan("");
  int window_size = 0;

  std::optional<WeightAverage> average;
  if (params.weight_averaging > 0.0) average.emplace(net->parameters(), params.weight_averaging);

  ProgressBar progress("train", static_cast<std::size_t>(params.batches));
  for (int batch = 1; batch <= params.batches; ++batch) {
    for (int b = 0; b < params.batch_size; ++b) {
      batch_sequences[b] = &data.sequences[training[pick_sequence(rng)]];
      sampler.draw(*batch_sequences[b], params.rotate, rng, batch_images.data() + b * set_floats);
    }
    optimiser.zero_grad();
    const torch::Tensor loss = perceptual_loss(
        net->forward(view_sets(batch_images, params.batch_size, params.set_size, data.size)),
        targets_tensor(batch_sequences), weights);
    loss.backward();
    optimiser.step();
    if (average) average->update(net->parameters());
    window_loss += loss.item<double>();
    ++window_size;
    progress.advance();

    if (batch % params.log_every != 0 && batch != params.batches) continue;
    last_train_loss = window_loss / window_size;
    window_loss = 0.0;
    window_size = 0;
    nlohmann::json entry{{"batch", batch}, {"train_loss", last_train_loss}};
    if (validation_set_count == 0) {
      log().info("batch {}/{}: training loss {:.5f}", batch, params.batches, last_train_loss);
    } else {
      if (average) average->exchange(net->parameters());
      net->eval();
      const torch::Tensor outputs = evaluate_outputs(
          net, validation_sets.images, validation_set_count, params.set_size, data.size);
      const double validation_loss =
          perceptual_loss(outputs, validation_sets.targets, weights).item<double>();
      net->train();
      entry["validation_loss"] = validation_loss;
      entry["validation_mae"] = target_errors(outputs, validation_sets.targets);
      log().info("batch {}/{}: training loss {:.5f}, validation loss {:.5f}{}", batch,
                 params.batches, last_train_loss, validation_loss,
                 average ? " (averaged weights)" : "");
      best_parameters.offer(net->parameters(), validation_loss, batch);
      if (average) average->exchange(net->parameters());
    }
    history.push_back(entry);
  }
  progress.finish();

  // Without validation nothing was kept: the average itself is the result.
  if (average && best_parameters.step() < 0) average->exchange(net->parameters());
  if (best_parameters.restore(net->parameters()))
    log().info("kept the weights of batch {} (lowest validation loss {:.5f})",
               best_parameters.step(), best_parameters.loss());
  net->export_weights(model);

  nlohmann::json final_losses{{"train_loss", last_train_loss}};
  if (best_parameters.step() > 0)
    final_losses.update(
        {{"best_batch", best_parameters.step()}, {"validation_loss", best_parameters.loss()}});
  const double seconds = watch.elapsed_s();
  model.training_info = {{"batches", params.batches},
                         {"batch_size", params.batch_size},
                         {"set_size", params.set_size},
                         {"learning_rate", params.learning_rate},
                         {"optimiser", "Adam(beta1 0.9, beta2 0.999)"},
                         {"loss", "paper 1 eq. (5), Lab / 100, c and d unscaled"},
                         {"lambda_d", params.loss.lambda_d},
                         {"lambda_l", params.loss.lambda_l},
                         {"rotate", params.rotate},
                         {"weight_averaging", params.weight_averaging},
                         {"seed", params.seed},
                         {"validation_fraction", params.validation_fraction},
                         {"validation_sets_per_sequence", params.validation_sets},
                         {"training_sequences", training.size()},
                         {"validation_sequences", validation.size()},
                         {"threads", threads},
                         {"parameter_count", model.parameter_count()},
                         {"history", history},
                         {"final", final_losses},
                         {"seconds", seconds},
                         {"batches_per_second", seconds > 0 ? params.batches / seconds : 0.0}};
  return model;
}

std::vector<float> torch_predict(const HemiCnn& model, const float* images, int sets, int count) {
  model.check();
  if (sets < 1 || count < 1)
    throw Error("HemiCNN input", "",
                fmt::format("needs >= 1 set of >= 1 image, got {} x {}", sets, count));
  HemiNet net(model.config);
  net->import_weights(model);
  net->eval();
  std::vector<float> buffer(images,
                            images + static_cast<std::size_t>(sets) * count * model.image_floats());
  const torch::Tensor outputs =
      evaluate_outputs(net, buffer, sets, count, model.image_size()).contiguous();
  const float* data = outputs.data_ptr<float>();
  return {data, data + outputs.numel()};
}

}  // namespace glint::reflectance
