#pragma once
// The whole BoundED pass over a cloud: features at the model's scales, then the network.
#include <cstdint>
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
// A gated model runs both of its networks on the features and keeps one for the whole cloud.
Classification classify(const PointCloud& cloud, const Model& model,
                        const std::vector<int>& scales = {});
// The network part alone, on features computed at the model's scale count (several models
// with the same scales can share one feature matrix); features_s stays 0.
Classification classify_features(const FeatureMatrix& features, const Model& model);

// Both answers of a gated model for every point, the choice left open (tiled classification
// makes it once for the whole file, from every tile's core points).
struct GatedClassification {
  Classification model_network;    // the model's own network
  Classification gate_network;     // the gate's network
  std::vector<float> gate_values;  // each point's value for GateTally::add
};
// Throws glint::Error for a model without a gate, and as classify().
GatedClassification classify_gated(const PointCloud& cloud, const Model& model,
                                   const std::vector<int>& scales = {});

// Adds the output attributes of docs/edges.md: uchar scalar_label, float scalar_p_sharp,
// float scalar_p_boundary, and uchar red/green/blue (red = sharp, green = boundary, grey = rest).
void attach_classification(PointCloud& cloud, const Classification& result);

}  // namespace glint::edges
