#pragma once
// The HemiCNN (paper 1 §3.6; Kim et al. 2017): a siamese CNN that maps a set of HemiImages of
// one segment to one Ward material in the perceptual parametrisation of eq. (5)
// (render/perceptual.h). Definition, fast plain-C++ inference and the JSON model file;
// training (libtorch) lives in reflectance/hemicnn_train.h.
//
// Network, for `count` (normally 25) hemi-images of 3 x S x S (S = 15) linear radiances (or
// reflectances, config.input) each:
//   input         x' = (log1p(x) - input_mean[c]) / input_std[c] per channel c, x clamped to
//                 [0, 1e30] (NaN counts as 0): log1p compresses highlights but keeps absolute
//                 scale (kd is absolute); the fixed per-channel standardisation comes from the
//                 training images
//   branch        (shared weights; one per hemi-image) for each of conv_channels a 3x3
//                 convolution, stride 2, padding 1, + LeakyReLU (15 -> 8 -> 4 -> 2 pixels with
//                 the defaults); flatten (y, x, channel) -> Linear(branch_features) + LeakyReLU
//   pooling       mean over the branches (order-invariant; any count >= 1)
//   head          Linear(head_hidden) + LeakyReLU -> Linear(7) = standardised
//                 (L, a, b, c_r, c_g, c_b, d); de-standardised with target_mean / target_std;
//                 then clamped: L to [0, 100], c >= 0, d to [kMinD, kMaxD]
// With the defaults (conv 16, 32, 32; 128; 64) this has 39,559 trainable parameters (about
// 0.9 MB as JSON) and costs 155k multiply-adds per hemi-image: predict() takes ~0.3 ms per set
// of 25 on one core of the project's CPU. Why so small: libtorch trains it on one CPU core at
// 44-55 batches of 32 sets per second; a stride-1 first layer (16 channels at 15 x 15) trained
// 4-5x slower. Weight layouts are TensorFlow's (the paper trained in TensorFlow), which suit
// vectorising over output channels: conv [ky][kx][in][out] (HWIO), dense [in][out].
#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "reflectance/hemi_image.h"
#include "render/perceptual.h"

namespace glint::reflectance {

struct HemiCnnConfig {
  int image_size = 15;  // S: hemi-image pixels per side (HemiImageParams::size)
  HemiProjection projection = HemiProjection::parabolic;  // of the hemi-images it was trained on
  HemiInput input = HemiInput::radiance;                  // likewise
  std::vector<int> conv_channels{16, 32, 32};             // outputs of each 3x3 convolution
  int branch_features = 128;  // per-branch feature vector, averaged over the branches
  int head_hidden = 64;
  float leaky_slope = 0.01f;  // LeakyReLU negative slope
};

// Throws glint::Error when a config describes no network (sizes out of range, no convolution).
void check_config(const HemiCnnConfig& config);

// One layer: a 3x3 convolution (kernel 3, padding 1) or a dense layer (kernel 1, stride 1).
struct HemiCnnLayer {
  std::string name;  // "conv<i>", "branch", "head" or "output"
  int kernel = 1;    // 3: convolution, 1: dense
  int stride = 1;
  int input_size = 1, output_size = 1;  // pixels per side (1 for dense layers)
  int inputs = 0, outputs = 0;          // channels (convolution) or values (dense)
  std::vector<float> weights;           // conv: [ky][kx][in][out]; dense: [in][out]
  std::vector<float> bias;              // outputs
};

// The layers a config implies, in evaluation order, with zero weights.
std::vector<HemiCnnLayer> make_layers(const HemiCnnConfig& config);

// Reusable memory for HemiCnn::predict: one per thread. Grows on first use, then predict
// allocates nothing.
struct HemiCnnScratch {
  std::vector<float> buffer;
};

class HemiCnn {
 public:
  static constexpr int kTargets = 7;                     // L, a, b, c_r, c_g, c_b, d
  static constexpr float kMinD = 0.65f, kMaxD = 0.999f;  // alpha in [0.001, 0.35]
  static constexpr float kMinStd = 1e-6f;

  // Zero weights, identity standardisations (throws glint::Error for an invalid config).
  explicit HemiCnn(HemiCnnConfig config = {});

  HemiCnnConfig config;
  float input_mean[3] = {0, 0, 0}, input_std[3] = {1, 1, 1};  // of log1p(radiance)
  float target_mean[kTargets] = {50, 0, 0, 0, 0, 0, 0.9f};
  float target_std[kTargets] = {1, 1, 1, 1, 1, 1, 1};
  std::vector<HemiCnnLayer> layers;                         // see make_layers
  nlohmann::json training_info = nlohmann::json::object();  // free-form: how it was trained

  HemiProjection projection() const { return config.projection; }
  HemiInput input() const { return config.input; }
  int image_size() const { return config.image_size; }
  // Floats of one input hemi-image: 3 * image_size^2.
  std::size_t image_floats() const;
  // Trainable parameters (weights and biases; the standardisations are not counted).
  std::size_t parameter_count() const;

  // Reads and validates a model file (format, version, every key, shapes against the config,
  // finite values, the parameter count); throws glint::Error naming the file and the key.
  static HemiCnn load(const std::string& path);
  // Writes the model file atomically (floats with 9 significant digits: load() is exact).
  void save(const std::string& path) const;
  nlohmann::json to_json() const;
  // Throws glint::Error when the members are inconsistent (config, shapes, std < kMinStd).
  void check() const;

  // The material of one set of `count` >= 1 hemi-images, images[count][3][S][S] (CHW each,
  // linear radiance). The result does not depend on the order of the images. Thread-safe (const);
  // no allocation once `scratch` has grown. Throws glint::Error when count < 1. Expects a
  // consistent model (load() and training give one; call check() after editing members).
  render::PerceptualWard predict(const float* images, int count, HemiCnnScratch& scratch) const;
  // The same with a thread_local scratch.
  render::PerceptualWard predict(const float* images, int count) const;
  // The 7 de-standardised network outputs before clamping (L, a, b, c_r, c_g, c_b, d).
  void predict_raw(const float* images, int count, HemiCnnScratch& scratch, float* out) const;
};

// The clamped PerceptualWard of 7 raw outputs (see the header comment), and the 7 values of a
// PerceptualWard in output order.
render::PerceptualWard perceptual_from_outputs(const float* outputs);
std::array<float, HemiCnn::kTargets> to_targets(const render::PerceptualWard& perceptual);

// Eq. (5) of paper 1, the training loss:
//   lambda_d |(lambda_l dL, da, db)|^2 + |(dc_r, dc_g, dc_b, dd)|^2
// in glint's units: L, a, b divided by kLabUnit = 100 (L in [0, 1]), c and d as they are. On
// the training ranges (render/training_set.h) the spreads are then L 0.2, a/b ~0.3, c 0.06,
// d 0.08, so with the paper's weights neither term swamps the other (unscaled Lab would
// outweigh the specular term ~1000-fold and the lambdas could not shift the focus).
struct HemiCnnLossWeights {
  double lambda_d = 0.1, lambda_l = 0.3;  // paper 1 (the "modified" HemiCNN); Kim et al.: 1, 1
};
inline constexpr double kLabUnit = 100.0;
// The weight of each squared difference in output order: lambda_d lambda_l^2 / 100^2,
// lambda_d / 100^2 (a, b), 1 (c_r, c_g, c_b, d).
std::array<double, HemiCnn::kTargets> loss_weights(const HemiCnnLossWeights& weights);
double hemicnn_loss(const render::PerceptualWard& estimate, const render::PerceptualWard& truth,
                    const HemiCnnLossWeights& weights = {});

}  // namespace glint::reflectance
