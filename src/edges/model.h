#pragma once
// The BoundED classification network (thesis §5.4.2–5.4.3, Fig. 5.4): its definition, fast
// plain-C++ inference and its JSON model file. Training (libtorch) lives in edges/train.h.
//
// Network, for S scales of F features each (12, the thesis's; 13 with the angular gap, see
// edges/features.h) and C classes:
//   input standardisation   x' = (x - mean) / std per input column (S*F values, fixed, not trained)
//   pairwise fusion         binary tree over the scales as in PCEDNet: a node concatenates two
//                           vectors and maps them through Linear(2w, fusion_width) + LeakyReLU;
//                           levels repeat until two vectors remain (S = 4: nodes (s0,s1), (s2,s3))
//   head                    hidden_layers x [Linear(.., hidden) + LeakyReLU + Dropout(p)]
//                           then Linear(hidden, C) + softmax (dropout is off at inference)
// With the defaults (S = 4, F = 12, C = 3) this has 2*300 + 400 + 272 + 272 + 51 = 1,595
// trainable parameters (the thesis's "1.6k"); with C = 2 it has 1,578; with F = 13 the first
// fusion level has 2*24 more (1,643 and 1,626).
//
// Classes: index = glint point label: 0 non-edge, 1 sharp edge, 2 boundary (C = 3 only).
//
// A model file may hold a gate: a second network of the same config but for its neighbour
// weights that answers a whole cloud instead of the first when the cloud's gate statistic says so
// (GateKind; docs/edges.md, "gate"). The second network may hold a gate of its own, so a file
// holds a chain of networks; each cloud gets one of them.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "edges/features.h"

namespace glint::edges {

struct ModelConfig {
  int classes = 3;                           // 3: non-edge/sharp/boundary; 2: non-edge/sharp
  std::vector<int> scales{128, 64, 32, 16};  // k of each feature scale, as given to the features
  int fusion_width = 12;                     // outputs of every fusion node
  int hidden = 16;                           // width of each hidden head layer
  int hidden_layers = 3;                     // number of hidden head layers
  float leaky_slope = 0.01f;                 // LeakyReLU negative slope
  bool angular_gap = false;                  // inputs: the thesis's 12 per scale, or 13
  bool area_weights = false;                 // neighbours weighed by area (edges/features.h)
  int features_per_scale() const { return edges::features_per_scale(angular_gap); }
  // Input columns of the network: the feature row of one point.
  std::size_t input_columns() const { return scales.size() * std::size_t(features_per_scale()); }
  FeatureParams feature_params() const { return FeatureParams{scales, angular_gap, area_weights}; }
  bool operator==(const ModelConfig&) const = default;
};

// Throws glint::Error when a config cannot describe a network: classes not 2 or 3, scale
// count not a power of two >= 2, scales not valid for the features (see check_scales), or a
// width / layer count / slope out of range.
void check_config(const ModelConfig& config);

// One fully connected layer: output = weights * input + bias.
struct DenseLayer {
  std::string name;  // "fusion<level>.<node>", "hidden<i>" or "output"
  int inputs = 0;
  int outputs = 0;
  std::vector<float> weights;  // outputs x inputs, row-major (the layout of torch's nn::Linear)
  std::vector<float> bias;     // outputs
};

// The dense layers a config implies, in evaluation order (fusion level by level, node by node;
// then the hidden layers; then the output layer), with zero weights.
std::vector<DenseLayer> make_layers(const ModelConfig& config);

// What a gate reads from each point it reads (gate_reads) and when its network answers the
// whole cloud. Both read before the cloud's features, so only the chosen network runs.
enum class GateKind {
  // More than half of the points have edges::noise_statistic below the threshold, from feature
  // rows of the gated model's own inputs: a network trained on clean clouds.
  noise,
  // The spread of the points' spacings, ln(P90 / P10) of the distance to the
  // kAreaSpacingNeighbour-th nearest other point, is at least the threshold: a network trained
  // on the mesh vertices of tessellations (dense along feature curves, sparse on planes).
  sampling,
};

// What one gate decided for a cloud (or a file), for logs and reports.
struct GateDecision {
  GateKind kind = GateKind::noise;
  float threshold = 0;
  double statistic = 0;  // GateTally::statistic
  bool gate_network_answered = false;
};

// A gate's evidence summed over the points of a cloud, or over the core points of every tile
// of a file (counts add across tiles and ranks, so the choice is the whole file's).
class GateTally {
 public:
  // ln r of the sampling gate in bins of 1/kBinsPerUnit over [-kLogRange, kLogRange).
  static constexpr int kBinsPerUnit = 64;
  static constexpr int kLogRange = 40;

  GateTally(GateKind kind, float threshold);
  // One point's value: its noise statistic, or the squared distance to its
  // kAreaSpacingNeighbour-th nearest other point.
  void add(float value);
  // Adds another tally of the same gate (a tile's).
  void merge(const GateTally& other);
  // The counts to sum across ranks: points, quiet points, spacing bins.
  std::vector<std::uint64_t>& counts() { return counts_; }
  std::uint64_t points() const { return counts_[0]; }
  // Noise gate: the share of quiet points. Sampling gate: ln(P90 / P10) of the spacings, each
  // percentile the centre of the bin where the sorted points reach it.
  double statistic() const;
  bool gate_network_answers() const;
  // The statistic and the choice, with the gate's kind and threshold.
  GateDecision decision() const { return {kind_, threshold_, statistic(), gate_network_answers()}; }

 private:
  GateKind kind_;
  float threshold_;
  std::vector<std::uint64_t> counts_;
};

// The points a gate reads: every point of a cloud of up to gate_sample_size(kind), and about
// that many of a larger one, picked by a hash of the input index, so a tiled file picks the same
// points as the whole cloud. A sampling gate's 2^17 spacings put ln(P90 / P10) within a bin or
// two of the whole cloud's; a noise gate's 2^14 feature rows put the share of quiet points
// within about 1 % of it (binomial standard error at most 0.4 %) at the cost of 2^14 points'
// smallest-scale features (their lists are kept for the rows, see edges::SearchFindings).
inline constexpr std::uint64_t kSamplingGatePoints = std::uint64_t(1) << 17;
inline constexpr std::uint64_t kNoiseGatePoints = std::uint64_t(1) << 14;
inline std::uint64_t gate_sample_size(GateKind kind) {
  return kind == GateKind::sampling ? kSamplingGatePoints : kNoiseGatePoints;
}
bool gate_reads(GateKind kind, std::uint64_t index, std::uint64_t points);

// The name of the network that answered after these decisions (first gate first): each
// decision's "mesh-vertex" or "default" (sampling), "low-noise" or "noisy" (noise), joined by
// "/"; empty for an ungated model.
std::string network_name(const std::vector<GateDecision>& decisions);

class Model {
 public:
  // A network of the given config with zero weights, mean 0 and std 1 (call check_config first
  // or expect glint::Error).
  explicit Model(ModelConfig config = {});

  ModelConfig config;
  std::vector<float> input_mean;   // S*F, column order of FeatureMatrix rows
  std::vector<float> input_std;    // S*F, each >= kMinInputStd
  std::vector<DenseLayer> layers;  // see make_layers
  nlohmann::json training_info = nlohmann::json::object();  // free-form: how it was trained

  // The gate (none when gate_network is null): gate_network has this model's config but for
  // the neighbour weights, and may hold a gate of its own.
  std::shared_ptr<const Model> gate_network;
  GateKind gate_kind = GateKind::noise;
  float gate_threshold = 0;  // > 0, in the units of the gate's statistic (GateTally)
  bool gated() const { return gate_network != nullptr; }
  GateTally new_tally() const { return GateTally(gate_kind, gate_threshold); }
  // The chain of gated networks, this model first: each holds a gate, the next is its network.
  std::vector<const Model*> gate_chain() const;
  // The network that answers after `decisions` (first gate first; fewer than the chain holds
  // where a gate's own network answered).
  const Model& answering_network(const std::vector<GateDecision>& decisions) const;
  // This model with `network` (gated or not) behind a gate (checks that the configs match but
  // for the neighbour weights and the threshold is finite and > 0; throws glint::Error).
  Model with_gate(GateKind kind, Model network, float threshold) const;

  static constexpr float kMinInputStd = 1e-6f;

  // Reads and validates a model file (format, version, every key, array sizes, finite values,
  // layer shapes against the config, the parameter count); throws glint::Error naming the
  // file and the key.
  static Model load(const std::string& path);
  // Writes the model file (JSON, floats with 9 significant digits, so load() is exact).
  void save(const std::string& path) const;
  nlohmann::json to_json() const;

  // Trainable parameters of this network (weights and biases; the fixed standardisation and the
  // gate's network are not counted).
  std::size_t parameter_count() const;

  // Throws glint::Error when the members are inconsistent (config, array sizes, shapes, the
  // gate's network and threshold).
  void check() const;
  // Throws glint::Error when the features do not fit the model (scale count, value count).
  void check_features(const FeatureMatrix& features) const;

  // Classifies every point: probabilities (points x classes, row-major) and the argmax label.
  // Runs in parallel over batches of points. Throws glint::Error when the features have a
  // different number of scales than the model. Non-finite features give non-finite
  // probabilities (compute_features never produces them).
  void predict(const FeatureMatrix& features, std::vector<float>& probabilities,
               std::vector<std::uint8_t>& labels) const;

  // Points per network pass: the inner loops run over them, and a pass's activations stay in
  // L1/L2 cache.
  static constexpr std::size_t kBatch = 256;
  // Working memory of predict_rows, reused between calls.
  struct PredictScratch {
    std::vector<float> a, b;
  };
  // The same for count <= kBatch points whose feature rows are contiguous at `rows` (the
  // model's row size each): probabilities (count x classes) and labels. No checks: call
  // check() first.
  void predict_rows(const float* rows, std::size_t count, float* probabilities,
                    std::uint8_t* labels, PredictScratch& scratch) const;
};

}  // namespace glint::edges
