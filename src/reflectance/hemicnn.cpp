#include "reflectance/hemicnn.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "core/cpu_level.h"
#include "core/error.h"
#include "io/json_fields.h"
#include "io/json_report.h"
#include "reflectance/hemi_dataset.h"

namespace glint::reflectance {
namespace {

constexpr const char* kFormatName = "glint-hemicnn-model";
constexpr int kFormatVersion = 1;
constexpr const char* kTargetNames[HemiCnn::kTargets] = {"L", "a", "b", "c_r", "c_g", "c_b", "d"};

// Inputs are clamped to [0, kMaxRadiance] (NaN counts as 0).
constexpr float kMaxRadiance = 1e30f;

int conv_output_size(int input_size) { return (input_size - 1) / 2 + 1; }  // 3x3, stride 2, pad 1

// ---- inference kernels. Activations are stored pixel-major, channel fastest (HWC), so the
// ---- innermost loops run over contiguous output channels and vectorise.

// log(1 + x) for x >= 0 within 3e-7 relative (torch's log1p is exact to 1 ulp), vectorisable:
// 1 + x = m 2^e with m in [sqrt(1/2), sqrt(2)), log m = 2 atanh(s), s = (m - 1) / (m + 1), by
// its series to s^9 (|s| <= 0.172); `correction` restores what rounding 1 + x lost.
float log1p_nonnegative(float x) {
  const float u = 1.0f + x;
  const std::int32_t offset = std::bit_cast<std::int32_t>(u) - 0x3f3504f3;  // bits of sqrt(1/2)
  const float exponent = static_cast<float>(offset >> 23);
  const float m = std::bit_cast<float>((offset & 0x007fffff) + 0x3f3504f3);
  const float correction = (x - (u - 1.0f)) / u;
  const float f = m - 1.0f, s = f / (2.0f + f), z = s * s;
  const float series = 1.0f + z * (1.0f / 3 + z * (1.0f / 5 + z * (1.0f / 7 + z * (1.0f / 9))));
  return exponent * 0.693147180559945f + 2.0f * s * series + correction;
}

void leaky_relu(float* values, int count, float slope) {
  for (int i = 0; i < count; ++i) values[i] = values[i] > 0.0f ? values[i] : slope * values[i];
}

// kWidth floats in one register (GCC/Clang vector extension): 4 (SSE) in the baseline build, 8
// (AVX2) in the x86-64-v3 clone below. A fixed-size array of them stays in registers, where GCC
// keeps a plain float array in memory.
template <int kWidth>
struct FloatLanes;
template <>
struct FloatLanes<4> {
  using type = float __attribute__((vector_size(4 * sizeof(float))));
};
template <>
struct FloatLanes<8> {
  using type = float __attribute__((vector_size(8 * sizeof(float))));
};

// 3x3 convolution, stride 2, zero padding 1, then LeakyReLU: input n x n x inputs (HWC),
// output m x m x outputs (HWC). kOutputs > 0 (a multiple of kWidth) fixes the output count at
// compile time, so the sums stay in registers; 0 reads it from the layer.
template <int kOutputs, int kWidth>
void apply_conv(const HemiCnnLayer& layer, const float* __restrict input, float* __restrict output,
                float slope) {
  using Lanes = typename FloatLanes<kWidth>::type;
  const int n = layer.input_size, m = layer.output_size, inputs = layer.inputs;
  const int outputs = kOutputs > 0 ? kOutputs : layer.outputs;
  constexpr int kVectors = kOutputs > 0 ? kOutputs / kWidth : 1;
  for (int oy = 0; oy < m; ++oy)
    for (int ox = 0; ox < m; ++ox) {
      float* __restrict destination = output + static_cast<std::size_t>(oy * m + ox) * outputs;
      // Even and odd taps add into separate sums: with 8 lanes, two to four registers of sums
      // left one chain of dependent multiply-adds each, which waited on their latency.
      Lanes sum[kVectors], odd[kVectors] = {};
      if constexpr (kOutputs > 0)
        std::memcpy(sum, layer.bias.data(), sizeof(sum));
      else
        std::copy(layer.bias.begin(), layer.bias.end(), destination);
      // The taps inside the image: kx in [kx_begin, kx_end) reads a contiguous run of input
      // pixels, and their weights are contiguous too ([ky][kx][in][out]).
      const int kx_begin = ox == 0 ? 1 : 0, kx_end = std::min(3, n + 1 - 2 * ox);
      const int run = (kx_end - kx_begin) * inputs;
      for (int ky = 0; ky < 3; ++ky) {
        const int iy = 2 * oy + ky - 1;
        if (iy < 0 || iy >= n) continue;
        const float* pixels =
            input + static_cast<std::size_t>(iy * n + 2 * ox + kx_begin - 1) * inputs;
        const float* taps =
            layer.weights.data() + static_cast<std::size_t>((ky * 3 + kx_begin) * inputs) * outputs;
        if constexpr (kOutputs > 0) {
          const auto add_tap = [&](Lanes* sums, int j) {
            const float value = pixels[j];
            const float* __restrict weight = taps + static_cast<std::size_t>(j) * outputs;
            for (int v = 0; v < kVectors; ++v) {
              Lanes w;
              std::memcpy(&w, weight + kWidth * v, sizeof(w));
              sums[v] += value * w;
            }
          };
          int j = 0;
          for (; j + 1 < run; j += 2) {
            add_tap(sum, j);
            add_tap(odd, j + 1);
          }
          if (j < run) add_tap(sum, j);
        } else {
          for (int j = 0; j < run; ++j) {
            const float value = pixels[j];
            const float* __restrict weight = taps + static_cast<std::size_t>(j) * outputs;
            for (int o = 0; o < outputs; ++o) destination[o] += value * weight[o];
          }
        }
      }
      if constexpr (kOutputs > 0) {
        for (int v = 0; v < kVectors; ++v) sum[v] += odd[v];
        std::memcpy(destination, sum, sizeof(sum));
      }
      leaky_relu(destination, outputs, slope);
    }
}

// apply_conv with the output count fixed at compile time for the common widths.
template <int kWidth>
void apply_conv_layer(const HemiCnnLayer& layer, const float* input, float* output, float slope) {
  switch (layer.outputs) {
    case 8:
      return apply_conv<8, kWidth>(layer, input, output, slope);
    case 16:
      return apply_conv<16, kWidth>(layer, input, output, slope);
    case 32:
      return apply_conv<32, kWidth>(layer, input, output, slope);
    case 64:
      return apply_conv<64, kWidth>(layer, input, output, slope);
    default:
      return apply_conv<0, kWidth>(layer, input, output, slope);
  }
}

// output = input * weights + bias ([in][out] weights).
void apply_dense(const HemiCnnLayer& layer, const float* __restrict input,
                 float* __restrict output) {
  std::copy(layer.bias.begin(), layer.bias.end(), output);
  for (int i = 0; i < layer.inputs; ++i) {
    const float value = input[i];
    const float* __restrict weight =
        layer.weights.data() + static_cast<std::size_t>(i) * layer.outputs;
    for (int o = 0; o < layer.outputs; ++o) output[o] += value * weight[o];
  }
}

// Standardised log1p radiance of a hemi-image, CHW -> HWC into `standardised` (log1p into
// `scratch` first: contiguous, so it vectorises). Not inlined into the clones below, in which
// GCC left the log1p loop scalar.
[[gnu::noinline]] void standardise_input(const HemiCnn& network, const float* image, float* scratch,
                                         float* standardised) {
  const std::size_t pixels =
      static_cast<std::size_t>(network.config.image_size) * network.config.image_size;
  for (std::size_t i = 0; i < 3 * pixels; ++i)
    scratch[i] = log1p_nonnegative(image[i] > 0.0f ? std::min(image[i], kMaxRadiance) : 0.0f);
  for (int c = 0; c < 3; ++c) {
    const float mean = network.input_mean[c], inverse_std = 1.0f / network.input_std[c];
    for (std::size_t p = 0; p < pixels; ++p)
      standardised[p * 3 + c] = (scratch[c * pixels + p] - mean) * inverse_std;
  }
}

// One branch of the siamese network: the hemi-image `image` (CHW) -> its `features` (the branch
// layer's outputs after LeakyReLU). `current` and `next` hold the widest activation each.
template <int kWidth>
[[gnu::always_inline]] inline void run_branch(const HemiCnn& network, const float* image,
                                              float* current, float* next, float* features) {
  standardise_input(network, image, next, current);
  const std::vector<HemiCnnLayer>& layers = network.layers;
  for (std::size_t l = 0; l + 3 < layers.size(); ++l) {
    apply_conv_layer<kWidth>(layers[l], current, next, network.config.leaky_slope);
    std::swap(current, next);
  }
  const HemiCnnLayer& branch = layers[layers.size() - 3];
  apply_dense(branch, current, features);
  leaky_relu(features, branch.outputs, network.config.leaky_slope);
}

// The branches are nearly all of an estimate's arithmetic: compiled twice, with 8-lane AVX2 and
// FMA where the CPU has x86-64-v3 (picked once at run time; the build's baseline is plain
// x86-64) and 4-lane SSE otherwise. FMA rounds differently, so the two give estimates that
// differ in the last bits.
using BranchKernel = void (*)(const HemiCnn&, const float*, float*, float*, float*);

[[gnu::flatten]] void run_branch_baseline(const HemiCnn& network, const float* image,
                                          float* current, float* next, float* features) {
  run_branch<4>(network, image, current, next, features);
}

#if defined(__x86_64__)
[[gnu::target("arch=x86-64-v3"), gnu::flatten]] void run_branch_x86_64_v3(
    const HemiCnn& network, const float* image, float* current, float* next, float* features) {
  run_branch<8>(network, image, current, next, features);
}
#endif

BranchKernel branch_kernel() {
#if defined(__x86_64__)
  if (cpu_has_x86_64_v3()) return run_branch_x86_64_v3;
#endif
  return run_branch_baseline;
}

}  // namespace

void check_config(const HemiCnnConfig& config) {
  const std::string where = "HemiCNN config";
  if (config.image_size < kMinHemiImageSize || config.image_size > kMaxHemiImageSize)
    throw Error(where, "image_size",
                fmt::format("must be in [{}, {}], got {}", kMinHemiImageSize, kMaxHemiImageSize,
                            config.image_size));
  if (config.conv_channels.empty() || config.conv_channels.size() > 6)
    throw Error(where, "conv_channels",
                fmt::format("needs 1 to 6 convolutions, got {}", config.conv_channels.size()));
  for (int channels : config.conv_channels)
    if (channels < 1 || channels > 256)
      throw Error(where, "conv_channels", fmt::format("must be in [1, 256], got {}", channels));
  if (config.branch_features < 1 || config.branch_features > 1024)
    throw Error(where, "branch_features",
                fmt::format("must be in [1, 1024], got {}", config.branch_features));
  if (config.head_hidden < 1 || config.head_hidden > 1024)
    throw Error(where, "head_hidden",
                fmt::format("must be in [1, 1024], got {}", config.head_hidden));
  if (!std::isfinite(config.leaky_slope) || config.leaky_slope < 0.0f || config.leaky_slope >= 1.0f)
    throw Error(where, "leaky_slope", fmt::format("must be in [0, 1), got {}", config.leaky_slope));
}

std::vector<HemiCnnLayer> make_layers(const HemiCnnConfig& config) {
  std::vector<HemiCnnLayer> layers;
  auto add = [&](std::string name, int kernel, int input_size, int inputs, int outputs) {
    HemiCnnLayer layer;
    layer.name = std::move(name);
    layer.kernel = kernel;
    layer.stride = kernel == 3 ? 2 : 1;
    layer.input_size = input_size;
    layer.output_size = kernel == 3 ? conv_output_size(input_size) : 1;
    layer.inputs = inputs;
    layer.outputs = outputs;
    layer.weights.assign(static_cast<std::size_t>(kernel * kernel) * inputs * outputs, 0.0f);
    layer.bias.assign(outputs, 0.0f);
    layers.push_back(std::move(layer));
    return layers.back().output_size;
  };
  int size = config.image_size, channels = 3;
  for (std::size_t i = 0; i < config.conv_channels.size(); ++i) {
    size = add(fmt::format("conv{}", i), 3, size, channels, config.conv_channels[i]);
    channels = config.conv_channels[i];
  }
  add("branch", 1, 1, size * size * channels, config.branch_features);
  add("head", 1, 1, config.branch_features, config.head_hidden);
  add("output", 1, 1, config.head_hidden, HemiCnn::kTargets);
  return layers;
}

HemiCnn::HemiCnn(HemiCnnConfig model_config) : config(std::move(model_config)) {
  check_config(config);
  layers = make_layers(config);
}

std::size_t HemiCnn::image_floats() const {
  return 3 * static_cast<std::size_t>(config.image_size) * config.image_size;
}

std::size_t HemiCnn::parameter_count() const {
  std::size_t count = 0;
  for (const HemiCnnLayer& layer : layers) count += layer.weights.size() + layer.bias.size();
  return count;
}

void HemiCnn::check() const {
  check_config(config);
  const std::string where = "HemiCNN";
  for (int c = 0; c < 3; ++c)
    if (!(input_std[c] >= kMinStd && std::isfinite(input_std[c])) || !std::isfinite(input_mean[c]))
      throw Error(where, "input_std",
                  fmt::format("channel {}: std must be finite and >= {}", c, kMinStd));
  for (int t = 0; t < kTargets; ++t)
    if (!(target_std[t] >= kMinStd && std::isfinite(target_std[t])) ||
        !std::isfinite(target_mean[t]))
      throw Error(where, "target_std",
                  fmt::format("{}: std must be finite and >= {}", kTargetNames[t], kMinStd));
  const std::vector<HemiCnnLayer> expected = make_layers(config);
  if (layers.size() != expected.size())
    throw Error(
        where, "layers",
        fmt::format("the config implies {} layers, have {}", expected.size(), layers.size()));
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const HemiCnnLayer& layer = layers[l];
    const HemiCnnLayer& shape = expected[l];
    if (layer.kernel != shape.kernel || layer.stride != shape.stride ||
        layer.input_size != shape.input_size || layer.output_size != shape.output_size ||
        layer.inputs != shape.inputs || layer.outputs != shape.outputs ||
        layer.weights.size() != shape.weights.size() || layer.bias.size() != shape.bias.size())
      throw Error(where, shape.name,
                  fmt::format("expected kernel {}, {} inputs, {} outputs, {} weights", shape.kernel,
                              shape.inputs, shape.outputs, shape.weights.size()));
  }
}

nlohmann::json HemiCnn::to_json() const {
  check();
  nlohmann::json layer_array = nlohmann::json::array();
  for (const HemiCnnLayer& layer : layers)
    layer_array.push_back({{"name", layer.name},
                           {"kernel", layer.kernel},
                           {"stride", layer.stride},
                           {"inputs", layer.inputs},
                           {"outputs", layer.outputs},
                           {"weights", io::exact_float_array(layer.weights)},
                           {"bias", io::exact_float_array(layer.bias)}});
  return {
      {"format", kFormatName},
      {"version", kFormatVersion},
      {"image_size", config.image_size},
      {"projection", hemi_projection_name(config.projection)},
      {"input", hemi_input_name(config.input)},
      {"conv_channels", config.conv_channels},
      {"branch_features", config.branch_features},
      {"head_hidden", config.head_hidden},
      {"leaky_slope", io::exact_float(config.leaky_slope)},
      {"weight_layout", "conv [ky][kx][in][out], dense [in][out]; flatten order (y, x, channel)"},
      {"parameter_count", parameter_count()},
      {"input_transform", "log1p(max(input, 0))"},
      {"input_mean", io::exact_float_array(input_mean, 3)},
      {"input_std", io::exact_float_array(input_std, 3)},
      {"targets", kTargetNames},
      {"target_mean", io::exact_float_array(target_mean, kTargets)},
      {"target_std", io::exact_float_array(target_std, kTargets)},
      {"layers", layer_array},
      {"training", training_info.is_null() ? nlohmann::json::object() : training_info}};
}

void HemiCnn::save(const std::string& path) const { io::write_json(path, to_json()); }

HemiCnn HemiCnn::load(const std::string& path) {
  const io::JsonFields reader(path);
  const nlohmann::json root = reader.read_document(kFormatName, kFormatVersion);

  HemiCnnConfig config;
  config.image_size = reader.integer(root, "image_size");
  const nlohmann::json& projection = reader.member(root, "projection", "");
  if (!projection.is_string()) reader.fail("projection", "expected a string");
  config.projection = parse_hemi_projection(projection.get<std::string>(), path);
  if (root.contains("input"))  // model files before HemiInput hold radiance models
    config.input = parse_hemi_input(reader.string(root, "input"), path);
  const nlohmann::json& channels = reader.member(root, "conv_channels", "");
  if (!channels.is_array()) reader.fail("conv_channels", "expected an array of integers");
  config.conv_channels.clear();
  for (const nlohmann::json& value : channels) {
    if (!value.is_number_integer()) reader.fail("conv_channels", "expected an array of integers");
    config.conv_channels.push_back(value.get<int>());
  }
  config.branch_features = reader.integer(root, "branch_features");
  config.head_hidden = reader.integer(root, "head_hidden");
  config.leaky_slope = reader.finite_float(reader.member(root, "leaky_slope", ""), "leaky_slope");
  try {
    check_config(config);
  } catch (const Error& e) {
    reader.fail(e.element(), e.reason());
  }

  HemiCnn model(config);
  const std::vector<float> input_mean = reader.floats(root, "input_mean", 3);
  const std::vector<float> input_std = reader.floats(root, "input_std", 3);
  const std::vector<float> target_mean = reader.floats(root, "target_mean", kTargets);
  const std::vector<float> target_std = reader.floats(root, "target_std", kTargets);
  std::copy(input_mean.begin(), input_mean.end(), model.input_mean);
  std::copy(input_std.begin(), input_std.end(), model.input_std);
  std::copy(target_mean.begin(), target_mean.end(), model.target_mean);
  std::copy(target_std.begin(), target_std.end(), model.target_std);
  for (int c = 0; c < 3; ++c)
    if (!(model.input_std[c] >= kMinStd))
      reader.fail(fmt::format("input_std[{}]", c), fmt::format("must be >= {}", kMinStd));
  for (int t = 0; t < kTargets; ++t)
    if (!(model.target_std[t] >= kMinStd))
      reader.fail(fmt::format("target_std[{}]", t), fmt::format("must be >= {}", kMinStd));

  const nlohmann::json& layer_array = reader.member(root, "layers", "");
  if (!layer_array.is_array() || layer_array.size() != model.layers.size())
    reader.fail("layers", fmt::format("expected an array of {} layers", model.layers.size()));
  for (std::size_t l = 0; l < model.layers.size(); ++l) {
    HemiCnnLayer& layer = model.layers[l];
    const nlohmann::json& entry = layer_array[l];
    const std::string where = fmt::format("layers[{}]", l);
    const nlohmann::json& name = reader.member(entry, "name", where);
    if (!name.is_string() || name.get<std::string>() != layer.name)
      reader.fail(where + ".name", fmt::format("expected \"{}\"", layer.name));
    if (reader.integer(entry, "kernel", where) != layer.kernel ||
        reader.integer(entry, "stride", where) != layer.stride ||
        reader.integer(entry, "inputs", where) != layer.inputs ||
        reader.integer(entry, "outputs", where) != layer.outputs)
      reader.fail(where, fmt::format("the config implies kernel {}, stride {}, {} inputs and {} "
                                     "outputs",
                                     layer.kernel, layer.stride, layer.inputs, layer.outputs));
    layer.weights = reader.floats(entry, "weights", layer.weights.size(), where);
    layer.bias = reader.floats(entry, "bias", layer.bias.size(), where);
  }

  const nlohmann::json& count = reader.member(root, "parameter_count", "");
  if (!count.is_number_unsigned() || count.get<std::size_t>() != model.parameter_count())
    reader.fail("parameter_count",
                fmt::format("the layers hold {} parameters", model.parameter_count()));

  if (const auto training = root.find("training"); training != root.end()) {
    if (!training->is_object()) reader.fail("training", "expected an object");
    model.training_info = *training;
  }
  return model;
}

void HemiCnn::predict_raw(const float* images, int count, HemiCnnScratch& scratch,
                          float* out) const {
  if (count < 1)
    throw Error("HemiCNN input", "count", fmt::format("needs >= 1 hemi-image, got {}", count));
  const int size = config.image_size;
  const std::size_t pixels = static_cast<std::size_t>(size) * size;
  const HemiCnnLayer& branch = layers[layers.size() - 3];
  const HemiCnnLayer& head = layers[layers.size() - 2];
  const HemiCnnLayer& output = layers.back();

  // Scratch: two activation buffers (ping-pong), the branch output, its running sum, the head.
  std::size_t widest = 3 * pixels;
  for (const HemiCnnLayer& layer : layers)
    widest = std::max(
        widest, static_cast<std::size_t>(layer.output_size * layer.output_size) * layer.outputs);
  const std::size_t features = static_cast<std::size_t>(branch.outputs);
  const std::size_t needed = 2 * widest + 2 * features + head.outputs + output.outputs;
  if (scratch.buffer.size() < needed) scratch.buffer.resize(needed);
  float* current = scratch.buffer.data();
  float* next = current + widest;
  float* branch_out = next + widest;
  float* feature_sum = branch_out + features;
  float* hidden = feature_sum + features;
  float* result = hidden + head.outputs;

  static const BranchKernel run_branch_kernel = branch_kernel();
  std::fill(feature_sum, feature_sum + features, 0.0f);
  for (int k = 0; k < count; ++k) {
    run_branch_kernel(*this, images + static_cast<std::size_t>(k) * 3 * pixels, current, next,
                      branch_out);
    for (std::size_t f = 0; f < features; ++f) feature_sum[f] += branch_out[f];
  }
  const float inverse_count = 1.0f / static_cast<float>(count);
  for (std::size_t f = 0; f < features; ++f) feature_sum[f] *= inverse_count;
  apply_dense(head, feature_sum, hidden);
  leaky_relu(hidden, head.outputs, config.leaky_slope);
  apply_dense(output, hidden, result);
  for (int t = 0; t < kTargets; ++t) out[t] = result[t] * target_std[t] + target_mean[t];
}

render::PerceptualWard HemiCnn::predict(const float* images, int count,
                                        HemiCnnScratch& scratch) const {
  float outputs[kTargets];
  predict_raw(images, count, scratch, outputs);
  return perceptual_from_outputs(outputs);
}

render::PerceptualWard HemiCnn::predict(const float* images, int count) const {
  thread_local HemiCnnScratch scratch;
  return predict(images, count, scratch);
}

render::PerceptualWard perceptual_from_outputs(const float* outputs) {
  render::PerceptualWard result;
  result.lab = Eigen::Vector3f(std::clamp(outputs[0], 0.0f, 100.0f), outputs[1], outputs[2]);
  result.c = Eigen::Vector3f(outputs[3], outputs[4], outputs[5]).cwiseMax(0.0f);
  result.d = std::clamp(outputs[6], HemiCnn::kMinD, HemiCnn::kMaxD);
  return result;
}

std::array<float, HemiCnn::kTargets> to_targets(const render::PerceptualWard& p) {
  return {p.lab.x(), p.lab.y(), p.lab.z(), p.c.x(), p.c.y(), p.c.z(), p.d};
}

std::array<double, HemiCnn::kTargets> loss_weights(const HemiCnnLossWeights& weights) {
  const double lab = weights.lambda_d / (kLabUnit * kLabUnit);
  return {lab * weights.lambda_l * weights.lambda_l, lab, lab, 1.0, 1.0, 1.0, 1.0};
}

double hemicnn_loss(const render::PerceptualWard& estimate, const render::PerceptualWard& truth,
                    const HemiCnnLossWeights& weights) {
  const std::array<double, HemiCnn::kTargets> w = loss_weights(weights);
  const std::array<float, HemiCnn::kTargets> a = to_targets(estimate), b = to_targets(truth);
  double loss = 0.0;
  for (int t = 0; t < HemiCnn::kTargets; ++t) {
    const double difference = double(a[t]) - double(b[t]);
    loss += w[t] * difference * difference;
  }
  return loss;
}

}  // namespace glint::reflectance
