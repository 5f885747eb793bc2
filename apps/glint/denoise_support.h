#pragma once
// What `glint denoise run` and `glint denoise eval` share: the denoiser options
// (denoise/denoiser.h runs the methods).
#include <CLI/CLI.hpp>

#include "denoise/denoiser.h"

namespace glint::app {

// --config, --device, --seed, the per-value overrides, --nlm-h, --noise-method and --patch onto
// `settings`.
void add_denoiser_options(CLI::App& command, denoise::DenoiserSettings& settings);

}  // namespace glint::app
