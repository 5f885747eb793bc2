#pragma once
// Training of the BoundED network with libtorch (CPU, float32; thesis §5.4.3–5.4.4, §5.5.3).
// The header has no torch include: the trained weights come back as a plain edges::Model.
//
// Loss: focal loss (Lin et al. 2017), mean over the batch of -alpha_t (1 - p_t)^gamma log p_t,
// gamma = 2; alpha (per-class weights) is off by default, as in the thesis.
// Optimiser: Adam, beta 0.9 / 0.999, learning rate 1e-3; batches of 16,384 points drawn at
// random (with replacement) from the training points each iteration.
// Validation: a stratified fraction of the points (per class) is held out; its loss and
// per-class recall are logged every log_every iterations and the weights with the lowest
// validation loss are kept (the thesis picks runs by validation loss); then the non-edge
// decision offset is tuned on the same points (TrainParams::tune_threshold).
// Determinism: the same data, config, params and thread count give bit-identical weights
// (torch::manual_seed for initialisation and dropout, std::mt19937_64 for batches and the split).
// Threads: as many torch threads as TBB may use (glint --threads / glint::limit_threads).
#include <cstdint>
#include <vector>

#include "edges/features.h"
#include "edges/model.h"

namespace glint::edges {

struct TrainParams {
  int iterations = 3000;   // thesis: 3000 on Default/Default++, 8000 on ABC
  int batch_size = 16384;  // points per iteration
  double learning_rate = 1e-3;
  double focal_gamma = 2.0;
  std::vector<double> class_weights;  // focal alpha per class; empty = all 1
  double dropout = 0.5;               // in the classification layers
  std::uint64_t seed = 1;
  double validation_fraction = 0.05;  // of each class's points; 0 = no validation split
  int log_every = 100;                // iterations between validation evaluations / log lines
  // false: batches drawn uniformly from all training points (the thesis; the focal loss copes
  // with the imbalance). true: every batch holds the classes in equal numbers.
  bool balance_classes = false;
  // Decision threshold (our addition; the thesis does not say how its operating point was set):
  // after training, one offset is added to the non-edge logit (the output bias), chosen on the
  // validation points to maximise the mean F1 of the edge classes. Balanced batches learn the
  // classes as if equally frequent; this moves the operating point back to real frequencies.
  bool tune_threshold = true;
};

struct TrainingSet {
  FeatureMatrix features;
  std::vector<std::uint8_t> labels;  // one per point, already mapped to the model's classes
};

// Trains a network of the given config. The input standardisation (mean, std floored at
// Model::kMinInputStd) is computed from the training points. model.training_info gets the
// parameters, the class counts and the losses ("final": last training loss, best validation
// loss / accuracy / per-class recall and its iteration). Shows a progress bar on a terminal.
// Throws glint::Error on inconsistent data (sizes, scale count, labels >= classes, no points)
// or invalid params.
Model train_model(const TrainingSet& data, const ModelConfig& config, const TrainParams& params);

// The same network evaluated by libtorch (eval mode: dropout off): probabilities, points x
// classes, row-major. For checking Model::predict against the training framework.
std::vector<float> torch_predict(const Model& model, const FeatureMatrix& features);

}  // namespace glint::edges
