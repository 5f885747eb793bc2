#pragma once
// The training plugin's interface. libtorch costs about 0.4 s of process start-up, so only
// `glint edges train` loads it: train_model() is built into a loadable module
// (lib/glint/edges-train.so) that the executable opens with dlopen. Tests link the training
// code directly (glint_edges_train).
#include <string>

#include "core/plugin_call.h"
#include "core/resources.h"
#include "edges/train.h"

namespace glint::edges {

struct TrainPluginCall {
  const TrainingSet* data = nullptr;
  const ModelConfig* config = nullptr;
  const TrainParams* params = nullptr;
  PluginHostState host;  // the module follows the host's --quiet and interrupt flag
  Model* result = nullptr;
  PluginFailure failure;  // set when the call returns 1
};

// extern "C" entry point of the module: 0 on success, 1 on failure.
using TrainPluginEntry = int (*)(TrainPluginCall*);
inline constexpr const char* kTrainPluginEntry = "glint_train_plugin_entry";
inline constexpr PluginName kTrainPlugin{"edges-train.so", "GLINT_TRAIN_PLUGIN"};

}  // namespace glint::edges
