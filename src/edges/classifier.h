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
  // A gated model: what each gate asked decided, first gate first (Model::answering_network).
  std::vector<GateDecision> gates;
};

// Classifies every point. `scales` overrides the model's neighbourhood sizes (same count;
// e.g. for a much denser or sparser cloud than the training data); empty = the model's.
// A gated model keeps one network of its chain for the whole cloud: once the neighbour search
// is built, each gate reads the points gate_reads picks and passes the cloud on or not, and then
// only the chosen network's features are computed and only it runs.
Classification classify(const PointCloud& cloud, const Model& model,
                        const std::vector<int>& scales = {});
// The network part alone, on features computed at the model's scale count and inputs (several
// models with the same inputs can share one feature matrix); features_s stays 0. Throws
// glint::Error for a gated model, whose gates choose before the features (use classify()).
Classification classify_features(const FeatureMatrix& features, const Model& model);

// One network of a model's chain with its gate not asked (tiled classification asks the gates
// once for the whole file): `network`'s own weights on features at its inputs. Throws as
// classify().
Classification classify_ungated(const PointCloud& cloud, const Model& network,
                                const std::vector<int>& scales = {});

// The bit of a point's gate-read mask that says a gate of this kind reads it (gate_reads).
inline std::uint8_t gate_read_bit(GateKind kind) {
  return kind == GateKind::noise ? std::uint8_t(1) : std::uint8_t(2);
}
// The gate-read mask of the point of input index `index` of `points` for the gates of a chain
// (Model::gate_chain): the bits of the gates that read it (gate_reads).
std::uint8_t gate_read_mask(std::span<const Model* const> chain, std::uint64_t index,
                            std::uint64_t points);
// The tallies of every gate of the model's chain (Model::gate_chain), each over the points of
// `cloud` whose mask in `reads` (one per point) has its kind's bit, their values as classify()
// finds them (tiled classification sums the tallies of every tile's core points before it
// classifies a tile). Throws glint::Error for a model without a gate, when `reads` has another
// size and when `cloud` has fewer points than the largest scale.
std::vector<GateTally> gate_tallies(const PointCloud& cloud, const Model& model,
                                    std::span<const std::uint8_t> reads,
                                    const std::vector<int>& scales = {});

// Adds the output attributes of docs/edges.md: uchar scalar_label, float scalar_p_sharp,
// float scalar_p_boundary, and uchar red/green/blue (red = sharp, green = boundary, grey = rest).
void attach_classification(PointCloud& cloud, const Classification& result);

}  // namespace glint::edges
