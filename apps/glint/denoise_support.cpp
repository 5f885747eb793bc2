#include "denoise_support.h"

#include "cli_support.h"

namespace glint::app {

void add_denoiser_options(CLI::App& command, denoise::DenoiserSettings& settings) {
  command
      .add_option("--config", settings.config,
                  "full = the paper's settings (5 levels x 128 filters; GPU-sized), fast = "
                  "CPU-practical (4 x 16; DIP 1,200 iterations, S2S 800)")
      ->check(CLI::IsMember({"full", "fast"}))
      ->capture_default_str();
  command.add_option("--device", settings.device, "auto (CUDA when available), cpu or cuda")
      ->check(CLI::IsMember({"auto", "cpu", "cuda"}))
      ->capture_default_str();
  command.add_option("--seed", settings.seed, "Seed of every random choice")->capture_default_str();
  command
      .add_option("--iterations", settings.iterations, "Optimisation steps (overrides --config)")
      ->check(kPositive);
  command
      .add_option("--predictions", settings.predictions, "S2S: dropout samples averaged at the end")
      ->check(kPositive);
  command.add_option("--levels", settings.levels, "U-Net depth (overrides --config)")
      ->check(CLI::Range(1, 8));
  command
      .add_option("--channels", settings.channels, "U-Net filters per level (overrides --config)")
      ->check(kPositive);
  command.add_option("--lr", settings.learning_rate, "Adam learning rate (overrides --config)")
      ->check(kPositive);
  command
      .add_option("--input-noise", settings.input_noise,
                  "DIP: sigma of the per-iteration input perturbation (full 1/30, fast 0)")
      ->check(kNonNegative);
  command
      .add_option("--average", settings.average,
                  "Guided DIP: eq. (14)'s output average, 'uniform' (the paper's) or 'weighted' "
                  "(each pixel's rate scaled by its loss weight, so let-go pixels keep their "
                  "estimate; fast's default)")
      ->check(CLI::IsMember({"uniform", "weighted"}));
  command
      .add_option("--pd", settings.discard, "Guided S2S: p_d of eqs (17)-(18) (full 0.01, fast 1)")
      ->check(CLI::Range(0.0, 1.0));
  command.add_option("--dropout", settings.dropout, "S2S: decoder dropout rate (default 0.3)")
      ->check(CLI::Range(0.0, 0.95));
  command
      .add_option("--kappa-w", settings.kappa_w, "Guided DIP: warm-up iterations of eq. (16) (225)")
      ->check(kNonNegative);
  command.add_option("--kappa-r", settings.kappa_r, "Guided DIP: decay rate of eq. (16) (0.15)")
      ->check(kPositive);
  command.add_option("--kappa-c", settings.kappa_c, "Guided DIP: weight floor of eq. (16) (0.02)")
      ->check(CLI::Range(0.0, 1.0));
  command
      .add_option("--kappa-m", settings.kappa_m, "Guided S2S: importance exponent of eq. (19) (2)")
      ->check(kPositive);
  command
      .add_option("--nlm-h", settings.nlm.h,
                  "NLM: filter strength on the 0-255 scale (also hColor)")
      ->check(kPositive)
      ->capture_default_str();
  command
      .add_option("--noise-method", settings.noise_method,
                  "Guidance from the input when --guidance is not given: svd or var")
      ->check(CLI::IsMember({"svd", "var", "variance"}))
      ->capture_default_str();
  command.add_option("--patch", settings.patch, "Noise-level patch size (odd)")
      ->capture_default_str();
}

}  // namespace glint::app
