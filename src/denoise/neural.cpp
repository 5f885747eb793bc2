#include "denoise/neural.h"

#include "core/error.h"

namespace glint::denoise {

bool is_guided(NeuralMethod method) {
  return method == NeuralMethod::guided_dip || method == NeuralMethod::guided_s2s;
}

bool is_self2self(NeuralMethod method) {
  return method == NeuralMethod::s2s || method == NeuralMethod::guided_s2s;
}

const char* method_name(NeuralMethod method) {
  switch (method) {
    case NeuralMethod::dip:
      return "dip";
    case NeuralMethod::guided_dip:
      return "guided-dip";
    case NeuralMethod::s2s:
      return "s2s";
    case NeuralMethod::guided_s2s:
      return "guided-s2s";
  }
  return "?";
}

NeuralMethod parse_neural_method(const std::string& name) {
  for (NeuralMethod m :
       {NeuralMethod::dip, NeuralMethod::guided_dip, NeuralMethod::s2s, NeuralMethod::guided_s2s})
    if (name == method_name(m)) return m;
  throw Error("--method", name, "unknown neural denoiser (dip, guided-dip, s2s, guided-s2s)");
}

NeuralParams neural_preset(NeuralMethod method, const std::string& config) {
  NeuralParams p;
  p.method = method;
  const bool s2s = is_self2self(method);
  // Plain Self2Self is the guided one with p_imp = 0 and p_d = 1 (§3.3).
  if (!is_guided(method)) p.masks.discard = 1.0;
  if (config == "full") {
    // DIP: the official denoising notebook; S2S: the official code (Adam 1e-4, 150k steps,
    // 100 averaged predictions, dropout 0.3) on the same U-Net.
    p.iterations = s2s ? 150000 : 3000;
    p.learning_rate = s2s ? 1e-4 : 0.01;
    return p;
  }
  if (config == "fast") {
    // Sized so a 256×256 colour image takes under two minutes on two CPU cores (chosen on
    // skimage crops, never on the Kodak evaluation images).
    p.net = UNetConfig{4, 16, 4};
    p.learning_rate = s2s ? 2e-3 : 0.01;
    p.predictions = 50;
    // p_d = 1, as the paper used for natural images (Fig. 9): with p_d = 0.01 a noisy pixel is
    // a loss target in only 0.3 % of the steps, which a run this short cannot afford.
    p.masks.discard = 1.0;
    if (s2s) {
      p.iterations = 800;
      return p;
    }
    // DIP: without the input perturbation the small net reaches the noise-fitting phase within
    // the budget (the noisy parts peak after 300-550 steps, the clean parts after ~1,000), which
    // is the phase the guided loss (κ as the paper's) is for; the weighted average keeps the
    // estimate of a let-go pixel from drifting with the unconstrained output.
    p.iterations = 1200;
    p.input_perturbation = 0.0;
    p.weighted_averaging = true;
    return p;
  }
  throw Error("--config", config, "unknown configuration (full, fast)");
}

}  // namespace glint::denoise
