#pragma once
// The HemiCNN training plugin's interface. libtorch costs about 0.4 s of process start-up, so
// only `glint hemicnn train` loads it: train_hemicnn() is built into a loadable module
// (lib/glint/hemicnn-train.so) that the executable opens with dlopen. Tests link the training
// code directly (glint_reflectance_train).
#include "core/plugin_call.h"
#include "core/resources.h"
#include "reflectance/hemicnn_train.h"

namespace glint::reflectance {

struct HemiCnnPluginCall {
  const HemiDataset* data = nullptr;
  const HemiCnnConfig* config = nullptr;
  const HemiCnnTrainParams* params = nullptr;
  PluginHostState host;  // the module follows the host's --quiet and interrupt flag
  HemiCnn* result = nullptr;
  PluginFailure failure;  // set when the call returns 1
};

// extern "C" entry point of the module: 0 on success, 1 on failure.
using HemiCnnPluginEntry = int (*)(HemiCnnPluginCall*);
inline constexpr const char* kHemiCnnPluginEntry = "glint_hemicnn_plugin_entry";
inline constexpr PluginName kHemiCnnPlugin{"hemicnn-train.so", "GLINT_HEMICNN_PLUGIN"};

}  // namespace glint::reflectance
