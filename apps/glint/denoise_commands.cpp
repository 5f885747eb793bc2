// `glint denoise`: guided neural denoising (thesis ch. 4, the guided-denoising paper).
#include "commands.h"

namespace glint::app {

void register_denoise_commands(CLI::App& app) {
  CLI::App* denoise = app.add_subcommand(
      "denoise",
      "Locally-guided denoising of images with spatially varying noise: noise-level and\n"
      "guidance maps, guided Deep Image Prior and guided Self2Self, the NLM baseline and the\n"
      "evaluation protocol.");
  denoise->require_subcommand(1);
  register_denoise_noise_map(*denoise);
  register_denoise_run(*denoise);
  register_denoise_eval(*denoise);
}

}  // namespace glint::app
