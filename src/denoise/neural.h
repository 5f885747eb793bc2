#pragma once
// The neural denoisers' settings and entry point: Deep Image Prior and Self2Self, each plain or
// guided by a guidance map (the guided-denoising paper, §3.2-3.3). Free of libtorch: the CLI
// includes it and calls the implementation through the plugin (denoise_plugin.h).
#include <cstdint>
#include <functional>
#include <string>

#include "core/image.h"
#include "denoise/loss_weights.h"
#include "denoise/s2s_masks.h"

namespace glint::denoise {

enum class NeuralMethod { dip, guided_dip, s2s, guided_s2s };
bool is_guided(NeuralMethod method);
bool is_self2self(NeuralMethod method);
const char* method_name(NeuralMethod method);

// The U-Net of DIP's denoising setup: `levels` stride-2 double-convolution blocks of
// `channels` filters, 1×1 skip branches of `skip_channels`, bilinear upsampling, batch norm,
// LeakyReLU 0.2, reflection padding, sigmoid output.
struct UNetConfig {
  int levels = 5;
  int channels = 128;
  int skip_channels = 4;
};

struct NeuralParams {
  NeuralMethod method = NeuralMethod::guided_s2s;
  UNetConfig net;
  int iterations = 3000;        // optimisation steps
  double learning_rate = 0.01;  // Adam
  // Deep Image Prior (§3.2).
  int input_channels = 32;  // fixed input U[0, input_scale]
  double input_scale = 0.1;
  double input_perturbation = 1.0 / 30.0;  // σ of the per-iteration input noise
  double averaging = 0.99;                 // output EMA, eq. (14)
  // Guided DIP: scale eq. (14)'s rate per pixel by w_dec, so the average stops following a
  // pixel once its loss weight has decayed (per-pixel early stopping of the estimate as well as
  // the loss; glint's addition, off in the paper's "full" settings). Without it the output of
  // a small net drifts where nothing constrains it any more.
  bool weighted_averaging = false;
  DecayParams decay;  // guided loss weights, eq. (16)
  // Self2Self (§3.3).
  MaskParams masks;
  double dropout = 0.3;   // decoder dropout rate before eq. (24)'s modulation
  int predictions = 100;  // test-time dropout samples averaged
  bool flips = true;      // random left-right / up-down flips of each sample
  // Run control.
  std::uint64_t seed = 1;
  std::string device = "auto";  // auto | cpu | cuda
  int threads = 0;              // intra-op threads on the CPU (0 = every core)
  int snapshot_every = 0;       // call `snapshot` every N iterations (0 = never)
  std::function<void(int iteration, const ImageF& estimate)> snapshot;
};

// The paper's settings ("full": 5 levels × 128 filters, DIP 3,000 iterations, S2S as the
// official code) or the CPU-practical "fast" configuration; any other name -> glint::Error.
NeuralParams neural_preset(NeuralMethod method, const std::string& config);
NeuralMethod parse_neural_method(const std::string& name);

struct NeuralStats {
  int iterations = 0;
  int predictions = 0;
  double seconds = 0;
  std::string device;
  std::int64_t parameters = 0;
};

// Denoises `noisy` (values in [0,1], any channel count). Guided methods need `guidance`
// (1 channel, same size, 1 = keep, 0 = noisy); unguided ones ignore it.
ImageF denoise_neural(const ImageF& noisy, const ImageF* guidance, const NeuralParams& params,
                      NeuralStats* stats = nullptr);

}  // namespace glint::denoise
