#pragma once
// Training of the HemiCNN with libtorch (CPU, float32; paper 1 §3.6, §4.1). The header has no
// torch include: the trained weights come back as a plain reflectance::HemiCnn.
//
// Examples: each is one random sequence of the training split and `set_size` (25) distinct
// random hemi-images of it, drawn on the fly (the paper draws 200 fixed sets per sequence), all
// rotated by the same random multiple of 90 degrees when `rotate` is on (a turn of the
// hemi-image is a turn of the tangent frame, which an isotropic BRDF does not see; mirror
// flips are not used).
// Loss: eq. (5), hemicnn_loss (reflectance/hemicnn.h), on the de-standardised outputs, mean
// over the batch. Optimiser: Adam (0.9, 0.999), learning rate 1e-4, batches of 32 sets (the
// paper: 150k batches on a GPU; glint's default fits ~10 minutes on a 2-core CPU).
// Validation: the last validation_fraction of the sequences (by index) are held out; from
// each, validation_sets fixed random sets are drawn once; their mean loss is logged every
// log_every batches and the weights with the lowest validation loss are kept.
// Weight averaging (`weight_averaging` > 0): an exponential moving average of the weights
// (Polyak averaging) is kept beside them, validated and returned in their place; its decay
// ramps up as min(decay, (1 + t) / (10 + t)) over the first batches t, so the average does not
// keep the random initialisation.
// Standardisations: input mean/std per channel of log1p(radiance) over (up to 64 images of)
// every training sequence; target mean/std over the training sequences.
// Determinism: the same data, config, params and thread count give bit-identical weights
// (torch::manual_seed for initialisation, std::mt19937_64 for the sets).
// Threads: `threads` torch threads, 1 by default: the tensors of this small net are too small
// to split, and on a 2-core machine 1 thread trained at 42-55 batches/s where 2 managed 5-20.
#include <cstdint>
#include <vector>

#include "reflectance/hemi_dataset.h"
#include "reflectance/hemicnn.h"

namespace glint::reflectance {

struct HemiCnnTrainParams {
  int batches = 25000;  // 8-10 minutes at the measured 44-55 batches/s (one thread)
  int batch_size = 32;  // sets per batch
  int set_size = 25;    // hemi-images per set (paper 1: 25 voxels per segment)
  double learning_rate = 1e-4;
  HemiCnnLossWeights loss;           // eq. (5): lambda_d 0.1, lambda_l 0.3 (Kim et al.: 1, 1)
  double validation_fraction = 0.1;  // last sequences by index; 0 = keep the last weights
  int validation_sets = 8;           // fixed sets per validation sequence
  int log_every = 500;               // batches between validation evaluations / log lines
  bool rotate = true;                // random quarter turns, the same for a whole set
  int threads = 1;                   // torch intra-op threads (see above)
  double weight_averaging = 0.0;     // decay of the weights' moving average; 0 = off
  std::uint64_t seed = 1;
};

// Trains a network of the given config on the dataset; config.image_size, config.projection
// and config.input are taken from the dataset. model.training_info gets the parameters, the
// split, the loss history and the best validation loss ("final"). Shows a progress bar on a
// terminal. Throws glint::Error for invalid params, an empty training split, or sequences with
// fewer images than set_size.
HemiCnn train_hemicnn(const HemiDataset& data, HemiCnnConfig config,
                      const HemiCnnTrainParams& params);

// The same network evaluated by libtorch: de-standardised outputs before clamping, sets x 7,
// for `sets` sets of `count` images each (images: sets x count x 3 x S x S). For checking
// HemiCnn::predict_raw against the training framework.
std::vector<float> torch_predict(const HemiCnn& model, const float* images, int sets, int count);

}  // namespace glint::reflectance
