#pragma once
// The whole BoundED pass over a cloud: features at the model's scales, then the network.
#include <cstdint>
#include <span>
#include <vector>

#include "core/point_cloud.h"
#include "edges/features.h"
#include "edges/model.h"

namespace glint::edges {

struct Classification {
  std::vector<std::uint8_t> labels;  // 0 non-edge, 1 sharp edge, 2 boundary
  std::vector<float> p_sharp;        // softmax probability of the sharp class
  std::vector<float> p_boundary;     // of the boundary class (0 for a 2-class model)
  // Wall-clock seconds of each stage; classify() runs them interleaved and splits its time
  // between them in proportion to the thread time each took.
  double features_s = 0;
  double inference_s = 0;
  // A gated model (Model::gated): the cloud's gate statistic (GateTally::statistic) and
  // whether the gate's network answered.
  double gate_statistic = 0;
  bool gate_network_answered = false;
};

// Classifies every point. `scales` overrides the model's neighbourhood sizes (same count;
// e.g. for a much denser or sparser cloud than the training data); empty = the model's.
// A gated model keeps one network for the whole cloud: a sampling gate chooses it from the
// spacings of the points sampling_gate_reads picks, before the features, and only it runs; a
// noise gate reads the features, so both networks run on them and one answer is kept.
Classification classify(const PointCloud& cloud, const Model& model,
                        const std::vector<int>& scales = {});
// The network part alone, on features computed at the model's scale count (several models
// with the same scales can share one feature matrix); features_s stays 0.
Classification classify_features(const FeatureMatrix& features, const Model& model);

// One network of a model, the gate not asked: the gate's network or the model's own (tiled
// classification asks the gate once for the whole file). Throws glint::Error when
// `gate_network` is set for a model without a gate, and as classify().
Classification classify_with_network(const PointCloud& cloud, const Model& model, bool gate_network,
                                     const std::vector<int>& scales = {});

// A sampling gate's tally of the points of `cloud` that `reads` marks (one entry per point),
// their spacings as classify() finds them (tiled classification sums the tallies of every
// tile's core points before it classifies a tile). Throws glint::Error for a model without a
// sampling gate and when `cloud` has fewer points than the largest scale.
GateTally sampling_gate_tally(const PointCloud& cloud, const Model& model,
                              std::span<const std::uint8_t> reads,
                              const std::vector<int>& scales = {});

// Both answers of a noise-gated model for every point, the choice left open (tiled
// classification makes it once for the whole file, from every tile's core points).
struct GatedClassification {
  Classification model_network;    // the model's own network
  Classification gate_network;     // the gate's network
  std::vector<float> gate_values;  // each point's noise statistic, for GateTally::add
};
// Throws glint::Error for a model without a noise gate, and as classify().
GatedClassification classify_gated(const PointCloud& cloud, const Model& model,
                                   const std::vector<int>& scales = {});

// Adds the output attributes of docs/edges.md: uchar scalar_label, float scalar_p_sharp,
// float scalar_p_boundary, and uchar red/green/blue (red = sharp, green = boundary, grey = rest).
void attach_classification(PointCloud& cloud, const Classification& result);

}  // namespace glint::edges
