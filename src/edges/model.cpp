#include "edges/model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "core/error.h"
#include "core/hash.h"
#include "core/parallel.h"
#include "io/json_fields.h"
#include "io/json_report.h"

namespace glint::edges {
namespace {

// The model file's key of a gate and of its network.
std::string gate_key(GateKind kind) {
  return kind == GateKind::noise ? "noise_gate" : "sampling_gate";
}
const char* gate_network_key(GateKind kind) {
  return kind == GateKind::noise ? "low_noise" : "mesh_vertices";
}

constexpr const char* kFormatName = "glint-bounded-model";
constexpr int kFormatVersion = 1;
constexpr std::size_t kBatch = Model::kBatch;

const std::vector<std::string>& class_names(int classes) {
  static const std::vector<std::string> three{"non-edge", "sharp-edge", "boundary"};
  static const std::vector<std::string> two{"non-edge", "sharp-edge"};
  return classes == 2 ? two : three;
}

bool is_power_of_two(std::size_t n) { return n != 0 && (n & (n - 1)) == 0; }

// ---- inference kernels; activations are stored feature-major: row r of a batch buffer holds
// ---- feature r of every point, so the innermost loops run over points and vectorise.

// output rows [0, outputs) = leaky(weights * input rows [0, inputs) + bias), for `count`
// points; leaky(x) = x > 0 ? x : slope·x, so slope 1 leaves the layer linear. The activation
// runs on each output row while it is still in cache.
// Compiled also for x86-64-v3: eight lanes and fused multiply-adds (logits then differ from
// the baseline's by float rounding).
#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void apply_dense(const DenseLayer& layer, const float* input, float* output, std::size_t count,
                 float slope) {
  for (int o = 0; o < layer.outputs; ++o) {
    float* out = output + static_cast<std::size_t>(o) * kBatch;
    const float bias = layer.bias[o];
    for (std::size_t b = 0; b < count; ++b) out[b] = bias;
    const float* weight_row = layer.weights.data() + static_cast<std::size_t>(o) * layer.inputs;
    for (int i = 0; i < layer.inputs; ++i) {
      const float weight = weight_row[i];
      const float* in = input + static_cast<std::size_t>(i) * kBatch;
      for (std::size_t b = 0; b < count; ++b) out[b] += weight * in[b];
    }
    for (std::size_t b = 0; b < count; ++b) out[b] = out[b] > 0.0f ? out[b] : slope * out[b];
  }
}

}  // namespace

void check_config(const ModelConfig& config) {
  const std::string where = "model config";
  if (config.classes != 2 && config.classes != 3)
    throw Error(where, "classes", fmt::format("must be 2 or 3, got {}", config.classes));
  if (config.scales.size() < 2 || !is_power_of_two(config.scales.size()))
    throw Error(where, "scales",
                fmt::format("the pairwise fusion needs a power of two >= 2 scales, got {}",
                            config.scales.size()));
  check_scales(config.scales);
  if (config.fusion_width < 1)
    throw Error(where, "fusion_width", fmt::format("must be >= 1, got {}", config.fusion_width));
  if (config.hidden < 1)
    throw Error(where, "hidden", fmt::format("must be >= 1, got {}", config.hidden));
  if (config.hidden_layers < 0)
    throw Error(where, "hidden_layers", fmt::format("must be >= 0, got {}", config.hidden_layers));
  if (!std::isfinite(config.leaky_slope) || config.leaky_slope < 0.0f || config.leaky_slope >= 1.0f)
    throw Error(where, "leaky_slope", fmt::format("must be in [0, 1), got {}", config.leaky_slope));
}

std::vector<DenseLayer> make_layers(const ModelConfig& config) {
  std::vector<DenseLayer> layers;
  auto add = [&](std::string name, int inputs, int outputs) {
    DenseLayer layer;
    layer.name = std::move(name);
    layer.inputs = inputs;
    layer.outputs = outputs;
    layer.weights.assign(static_cast<std::size_t>(inputs) * outputs, 0.0f);
    layer.bias.assign(outputs, 0.0f);
    layers.push_back(std::move(layer));
  };
  // Fusion tree: each level halves the number of vectors until two remain.
  int vectors = static_cast<int>(config.scales.size());
  int width = config.features_per_scale();
  for (int level = 0; vectors > 2; ++level, vectors /= 2, width = config.fusion_width)
    for (int node = 0; node < vectors / 2; ++node)
      add(fmt::format("fusion{}.{}", level, node), 2 * width, config.fusion_width);
  int inputs = 2 * width;
  for (int h = 0; h < config.hidden_layers; ++h, inputs = config.hidden)
    add(fmt::format("hidden{}", h), inputs, config.hidden);
  add("output", inputs, config.classes);
  return layers;
}

Model::Model(ModelConfig model_config) : config(std::move(model_config)) {
  check_config(config);
  const std::size_t columns = config.input_columns();
  input_mean.assign(columns, 0.0f);
  input_std.assign(columns, 1.0f);
  layers = make_layers(config);
}

std::size_t Model::parameter_count() const {
  std::size_t count = 0;
  for (const DenseLayer& layer : layers) count += layer.weights.size() + layer.bias.size();
  return count;
}

void Model::check() const {
  check_config(config);
  const std::string where = "model";
  const std::size_t columns = config.input_columns();
  if (input_mean.size() != columns || input_std.size() != columns)
    throw Error(where, "input_mean/input_std",
                fmt::format("expected {} values each, have {} and {}", columns, input_mean.size(),
                            input_std.size()));
  for (float s : input_std)
    if (!(s >= kMinInputStd))
      throw Error(where, "input_std", fmt::format("values must be >= {}", kMinInputStd));
  const std::vector<DenseLayer> expected = make_layers(config);
  if (layers.size() != expected.size())
    throw Error(
        where, "layers",
        fmt::format("the config implies {} layers, have {}", expected.size(), layers.size()));
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const DenseLayer& layer = layers[l];
    const DenseLayer& shape = expected[l];
    if (layer.inputs != shape.inputs || layer.outputs != shape.outputs ||
        layer.weights.size() != shape.weights.size() || layer.bias.size() != shape.bias.size())
      throw Error(where, shape.name,
                  fmt::format("expected {} x {} weights and {} biases", shape.outputs, shape.inputs,
                              shape.outputs));
  }
  if (gated()) {
    const std::string key = gate_key(gate_kind);
    ModelConfig other = gate_network->config;
    other.area_weights = config.area_weights;
    if (other != config)
      throw Error(where, key + "." + gate_network_key(gate_kind),
                  "the gate's network must have the model's config but for its neighbour weights");
    gate_network->check();
    if (!std::isfinite(gate_threshold) || gate_threshold <= 0.0f)
      throw Error(where, key + ".threshold",
                  fmt::format("must be finite and > 0, got {}", gate_threshold));
  }
}

Model Model::with_gate(GateKind kind, Model network, float threshold) const {
  if (gated()) throw Error("model", gate_key(gate_kind), "already has a gate");
  Model gated_model = *this;
  gated_model.gate_network = std::make_shared<const Model>(std::move(network));
  gated_model.gate_kind = kind;
  gated_model.gate_threshold = threshold;
  gated_model.check();
  return gated_model;
}

std::vector<const Model*> Model::gate_chain() const {
  std::vector<const Model*> chain;
  for (const Model* network = this; network->gated(); network = network->gate_network.get())
    chain.push_back(network);
  return chain;
}

const Model& Model::answering_network(const std::vector<GateDecision>& decisions) const {
  const Model* network = this;
  for (const GateDecision& decision : decisions) {
    if (!network->gated() || network->gate_kind != decision.kind)
      throw Error("model", "gate", "the decisions do not fit the model's gates");
    if (!decision.gate_network_answered) break;
    network = network->gate_network.get();
  }
  return *network;
}

std::string network_name(const std::vector<GateDecision>& decisions) {
  std::string name;
  for (const GateDecision& decision : decisions) {
    if (!name.empty()) name += '/';
    if (decision.kind == GateKind::noise)
      name += decision.gate_network_answered ? "low-noise" : "noisy";
    else
      name += decision.gate_network_answered ? "mesh-vertex" : "default";
  }
  return name;
}

GateTally::GateTally(GateKind kind, float threshold)
    : kind_(kind),
      threshold_(threshold),
      counts_(kind == GateKind::sampling ? 2 + 2 * kLogRange * kBinsPerUnit : 2, 0) {}

void GateTally::add(float value) {
  ++counts_[0];
  if (kind_ == GateKind::noise) {
    counts_[1] += value < threshold_;
    return;
  }
  // ln r = ln(r^2) / 2; a duplicate point's spacing 0 (and a NaN) falls in the lowest bin.
  const double bin = (0.5 * std::log(double(value)) + kLogRange) * kBinsPerUnit;
  const auto last = static_cast<double>(counts_.size() - 3);
  ++counts_[2 + static_cast<std::size_t>(bin >= 0.0 ? std::min(bin, last) : 0.0)];
}

void GateTally::merge(const GateTally& other) {
  if (other.kind_ != kind_ || other.counts_.size() != counts_.size())
    throw Error("gate", "tally", "tallies of different gates cannot be merged");
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
}

double GateTally::statistic() const {
  const std::uint64_t n = points();
  if (n == 0) return 0;
  if (kind_ == GateKind::noise) return double(counts_[1]) / double(n);
  // The centre of the bin in which the sorted values reach rank ceil(q n).
  const auto percentile = [&](double q) {
    const auto rank = std::max<std::uint64_t>(1, std::uint64_t(std::ceil(q * double(n))));
    std::uint64_t seen = 0;
    std::size_t bin = 2;
    for (; bin + 1 < counts_.size(); ++bin)
      if ((seen += counts_[bin]) >= rank) break;
    return (double(bin - 2) + 0.5) / kBinsPerUnit - kLogRange;
  };
  return percentile(0.9) - percentile(0.1);
}

bool GateTally::gate_network_answers() const {
  if (kind_ == GateKind::noise) return 2 * counts_[1] > points();
  return points() > 0 && statistic() >= threshold_;
}

bool gate_reads(GateKind kind, std::uint64_t index, std::uint64_t points) {
  const std::uint64_t sample = gate_sample_size(kind);
  if (points <= sample) return true;
  return mix64(index) < std::numeric_limits<std::uint64_t>::max() / points * sample;
}

namespace {

// The keys of one network: standardisation, layers, parameter count, training record.
nlohmann::json network_json(const Model& model) {
  nlohmann::json layer_array = nlohmann::json::array();
  for (const DenseLayer& layer : model.layers)
    layer_array.push_back({{"name", layer.name},
                           {"inputs", layer.inputs},
                           {"outputs", layer.outputs},
                           {"weights", io::exact_float_array(layer.weights)},
                           {"bias", io::exact_float_array(layer.bias)}});
  return {
      {"parameter_count", model.parameter_count()},
      {"input_mean", io::exact_float_array(model.input_mean)},
      {"input_std", io::exact_float_array(model.input_std)},
      {"layers", layer_array},
      {"training", model.training_info.is_null() ? nlohmann::json::object() : model.training_info}};
}

// Reads network_json's keys of `object` (key path `where`) into `model`, whose config is set.
void read_network(const io::JsonFields& reader, const nlohmann::json& object,
                  const std::string& where, Model& model) {
  const std::size_t columns = model.config.input_columns();
  model.input_mean = reader.floats(object, "input_mean", columns, where);
  model.input_std = reader.floats(object, "input_std", columns, where);
  for (std::size_t c = 0; c < columns; ++c)
    if (!(model.input_std[c] >= Model::kMinInputStd))
      reader.fail(io::key_path(where, fmt::format("input_std[{}]", c)),
                  fmt::format("must be >= {}", Model::kMinInputStd));

  const nlohmann::json& layer_array = reader.member(object, "layers", where);
  if (!layer_array.is_array() || layer_array.size() != model.layers.size())
    reader.fail(io::key_path(where, "layers"),
                fmt::format("expected an array of {} layers", model.layers.size()));
  for (std::size_t l = 0; l < model.layers.size(); ++l) {
    DenseLayer& layer = model.layers[l];
    const nlohmann::json& entry = layer_array[l];
    const std::string layer_key = io::key_path(where, fmt::format("layers[{}]", l));
    if (!entry.is_object()) reader.fail(layer_key, "expected an object");
    const nlohmann::json& name = reader.member(entry, "name", layer_key);
    if (!name.is_string() || name.get<std::string>() != layer.name)
      reader.fail(layer_key + ".name", fmt::format("expected \"{}\"", layer.name));
    const nlohmann::json& inputs = reader.member(entry, "inputs", layer_key);
    const nlohmann::json& outputs = reader.member(entry, "outputs", layer_key);
    if (inputs != layer.inputs || outputs != layer.outputs)
      reader.fail(layer_key,
                  fmt::format("the config implies a {} x {} layer", layer.outputs, layer.inputs));
    layer.weights = reader.floats(entry, "weights", layer.weights.size(), layer_key);
    layer.bias = reader.floats(entry, "bias", layer.bias.size(), layer_key);
  }

  const nlohmann::json& count = reader.member(object, "parameter_count", where);
  if (!count.is_number_unsigned() || count.get<std::size_t>() != model.parameter_count())
    reader.fail(io::key_path(where, "parameter_count"),
                fmt::format("the layers hold {} parameters", model.parameter_count()));

  if (const auto training = object.find("training"); training != object.end()) {
    if (!training->is_object()) reader.fail(io::key_path(where, "training"), "expected an object");
    model.training_info = *training;
  }
}

const char* weights_name(const ModelConfig& config) {
  return config.area_weights ? "area" : "count";
}

// The optional "neighbour_weights" of `object`: whether neighbours weigh by area (`otherwise`
// where the key is missing, as in files of earlier versions).
bool read_area_weights(const io::JsonFields& reader, const nlohmann::json& object,
                       const std::string& where, bool otherwise) {
  if (!object.contains("neighbour_weights")) return otherwise;
  const std::string weights = reader.string(object, "neighbour_weights", where);
  if (weights != "count" && weights != "area")
    reader.fail(io::key_path(where, "neighbour_weights"),
                fmt::format("expected \"count\" or \"area\", got \"{}\"", weights));
  return weights == "area";
}

// The model's gate into `object`: statistic, threshold and the gate's network, whose object
// holds its neighbour weights and its own gate.
void add_gate_json(const Model& model, nlohmann::json& object) {
  if (!model.gated()) return;
  nlohmann::json network = network_json(*model.gate_network);
  network["neighbour_weights"] = weights_name(model.gate_network->config);
  add_gate_json(*model.gate_network, network);
  const char* statistic = model.gate_kind == GateKind::noise
                              ? "sqrt(sigma_upper(3) + sigma_lower(3)), smallest scale"
                              : "ln(P90 / P10) of the distance to the 8th nearest other point";
  object[gate_key(model.gate_kind)] = {{"statistic", statistic},
                                       {"threshold", io::exact_float(model.gate_threshold)},
                                       {gate_network_key(model.gate_kind), network}};
}

// The gate of `object` (key path `where`), if it holds one, into `model`, whose network is read;
// the gate's network takes the model's config but for its neighbour weights.
void read_gate(const io::JsonFields& reader, const nlohmann::json& object, const std::string& where,
               Model& model) {
  for (const GateKind kind : {GateKind::noise, GateKind::sampling}) {
    const auto gate = object.find(gate_key(kind));
    if (gate == object.end()) continue;
    const std::string key = io::key_path(where, gate_key(kind));
    if (model.gated()) reader.fail(key, "a model holds one gate; this one has two");
    if (!gate->is_object()) reader.fail(key, "expected an object");
    const nlohmann::json& network_object = reader.member(*gate, gate_network_key(kind), key);
    const std::string network_key = key + "." + gate_network_key(kind);
    ModelConfig config = model.config;
    config.area_weights =
        read_area_weights(reader, network_object, network_key, model.config.area_weights);
    Model network(config);
    read_network(reader, network_object, network_key, network);
    read_gate(reader, network_object, network_key, network);
    model.gate_threshold =
        reader.finite_float(reader.member(*gate, "threshold", key), key + ".threshold");
    model.gate_kind = kind;
    model.gate_network = std::make_shared<const Model>(std::move(network));
    try {
      model.check();
    } catch (const Error& e) {
      reader.fail(io::key_path(where, e.element()), e.reason());
    }
  }
}

}  // namespace

nlohmann::json Model::to_json() const {
  check();
  nlohmann::json root = {{"format", kFormatName},
                         {"version", kFormatVersion},
                         {"classes", class_names(config.classes)},
                         {"scales", config.scales},
                         {"features_per_scale", config.features_per_scale()},
                         {"neighbour_weights", weights_name(config)},
                         {"fusion_width", config.fusion_width},
                         {"hidden", config.hidden},
                         {"hidden_layers", config.hidden_layers},
                         {"leaky_slope", io::exact_float(config.leaky_slope)}};
  root.update(network_json(*this));
  add_gate_json(*this, root);
  return root;
}

void Model::save(const std::string& path) const { io::write_json(path, to_json()); }

Model Model::load(const std::string& path) {
  const io::JsonFields reader(path);
  const nlohmann::json root = reader.read_document(kFormatName, kFormatVersion);

  const nlohmann::json& classes = reader.member(root, "classes");
  if (!classes.is_array() || (classes.size() != 2 && classes.size() != 3))
    reader.fail("classes", "expected a list of 2 or 3 class names");
  const int class_count = static_cast<int>(classes.size());
  if (classes != nlohmann::json(class_names(class_count)))
    reader.fail("classes",
                fmt::format("expected {}", nlohmann::json(class_names(class_count)).dump()));

  const int features = reader.integer(root, "features_per_scale");
  if (features != features_per_scale(false) && features != features_per_scale(true))
    reader.fail("features_per_scale",
                fmt::format("expected {} (the thesis's features) or {} (with the angular gap), "
                            "got {}",
                            features_per_scale(false), features_per_scale(true), features));

  ModelConfig config;
  config.angular_gap = features == features_per_scale(true);
  config.area_weights = read_area_weights(reader, root, "", false);
  config.classes = class_count;
  config.scales = reader.integers(root, "scales");
  config.fusion_width = reader.integer(root, "fusion_width");
  config.hidden = reader.integer(root, "hidden");
  config.hidden_layers = reader.integer(root, "hidden_layers");
  config.leaky_slope = reader.finite_float(reader.member(root, "leaky_slope"), "leaky_slope");
  try {
    check_config(config);
  } catch (const Error& e) {
    reader.fail(e.element(), e.reason());
  }

  Model model(config);
  read_network(reader, root, "", model);
  read_gate(reader, root, "", model);
  return model;
}

void Model::check_features(const FeatureMatrix& features) const {
  const int scales = static_cast<int>(config.scales.size());
  if (features.scales != scales)
    throw Error(
        "features", "scales",
        fmt::format("the model expects {} scales, the features have {}", scales, features.scales));
  if (features.per_scale != config.features_per_scale())
    throw Error("features", "per_scale",
                fmt::format("the model expects {} values per scale, the features have {}",
                            config.features_per_scale(), features.per_scale));
  if (features.values.size() != features.points * features.row_size())
    throw Error("features", "values",
                fmt::format("expected {} values for {} points, have {}",
                            features.points * features.row_size(), features.points,
                            features.values.size()));
}

void Model::predict_rows(const float* rows, std::size_t count, float* probabilities,
                         std::uint8_t* labels, PredictScratch& scratch) const {
  const int scales = static_cast<int>(config.scales.size());
  const std::size_t columns = config.input_columns();
  const std::size_t classes = static_cast<std::size_t>(config.classes);
  std::size_t widest = columns;
  for (const DenseLayer& layer : layers)
    widest = std::max(widest, static_cast<std::size_t>(layer.outputs));
  scratch.a.resize(widest * kBatch);
  scratch.b.resize(widest * kBatch);
  float* current = scratch.a.data();
  float* next = scratch.b.data();

  // Standardised inputs, transposed to feature-major.
  for (std::size_t b = 0; b < count; ++b) {
    const float* row = rows + b * columns;
    for (std::size_t c = 0; c < columns; ++c)
      current[c * kBatch + b] = (row[c] - input_mean[c]) / input_std[c];
  }

  // Fusion tree: node j of a level reads vectors 2j and 2j+1 (adjacent rows) and writes
  // vector j of the next level.
  std::size_t layer_index = 0;
  int width = config.features_per_scale();
  for (int vectors = scales; vectors > 2; vectors /= 2, width = config.fusion_width) {
    for (int node = 0; node < vectors / 2; ++node) {
      const DenseLayer& layer = layers[layer_index++];
      float* out = next + static_cast<std::size_t>(node) * layer.outputs * kBatch;
      apply_dense(layer, current + static_cast<std::size_t>(2 * node) * width * kBatch, out, count,
                  config.leaky_slope);
    }
    std::swap(current, next);
  }
  // Head.
  for (int h = 0; h < config.hidden_layers; ++h) {
    const DenseLayer& layer = layers[layer_index++];
    apply_dense(layer, current, next, count, config.leaky_slope);
    std::swap(current, next);
  }
  apply_dense(layers[layer_index], current, next, count, /*slope=*/1.0f);  // linear logits

  // Softmax and argmax per point.
  for (std::size_t b = 0; b < count; ++b) {
    float* out = probabilities + b * classes;
    float max_logit = next[b];
    std::size_t best = 0;
    for (std::size_t c = 1; c < classes; ++c)
      if (next[c * kBatch + b] > max_logit) {
        max_logit = next[c * kBatch + b];
        best = c;
      }
    float sum = 0.0f;
    for (std::size_t c = 0; c < classes; ++c) {
      out[c] = std::exp(next[c * kBatch + b] - max_logit);
      sum += out[c];
    }
    for (std::size_t c = 0; c < classes; ++c) out[c] /= sum;
    labels[b] = static_cast<std::uint8_t>(best);
  }
}

void Model::predict(const FeatureMatrix& features, std::vector<float>& probabilities,
                    std::vector<std::uint8_t>& labels) const {
  check();
  check_features(features);
  const std::size_t classes = static_cast<std::size_t>(config.classes);
  probabilities.resize(features.points * classes);
  labels.resize(features.points);
  parallel_for_chunks(features.points, kBatch, [&](std::size_t chunk_begin, std::size_t chunk_end) {
    PredictScratch scratch;
    for (std::size_t begin = chunk_begin; begin < chunk_end; begin += kBatch) {
      predict_rows(features.row(begin), std::min(kBatch, chunk_end - begin),
                   probabilities.data() + begin * classes, labels.data() + begin, scratch);
    }
  });
}

}  // namespace glint::edges
