#pragma once
// The neural denoisers as a loadable module (lib/glint/denoise-nets.so): libtorch costs about
// 0.4 s of process start-up, so only `glint denoise run|eval` with a neural method opens it.
// Tests link glint_denoise_nets directly.
#include <string>

#include "core/plugin_call.h"
#include "core/resources.h"
#include "denoise/neural.h"

namespace glint::denoise {

struct DenoisePluginCall {
  const ImageF* noisy = nullptr;
  const ImageF* guidance = nullptr;  // may be null for unguided methods
  const NeuralParams* params = nullptr;
  PluginHostState host;  // the module follows the host's --quiet and interrupt flag
  ImageF* result = nullptr;
  NeuralStats* stats = nullptr;
  PluginFailure failure;  // set when the call returns 1
};

// extern "C" entry point of the module: 0 on success, 1 on failure.
using DenoisePluginEntry = int (*)(DenoisePluginCall*);
inline constexpr const char* kDenoisePluginEntry = "glint_denoise_plugin_entry";
inline constexpr PluginName kDenoisePlugin{"denoise-nets.so", "GLINT_DENOISE_PLUGIN"};

}  // namespace glint::denoise
