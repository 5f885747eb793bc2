#pragma once
// The training plugin's interface. libtorch costs about 0.4 s of process start-up, so only
// `glint edges train` loads it: train_model() is built into a loadable module
// (libglint_train_plugin.so) that the executable opens with dlopen. Tests link the training
// code directly (glint_edges_train).
#include <string>

#include "edges/train.h"

namespace glint::edges {

struct TrainPluginCall {
  const TrainingSet* data = nullptr;
  const ModelConfig* config = nullptr;
  const TrainParams* params = nullptr;
  bool quiet = false;  // the module has its own copy of the progress-bar switch
  Model* result = nullptr;
  // Set when training fails (the module reports glint::Error's parts instead of throwing
  // across the module boundary).
  std::string error_file, error_element, error_reason;
};

// extern "C" entry point of the module: 0 on success, 1 on failure.
using TrainPluginEntry = int (*)(TrainPluginCall*);
inline constexpr const char* kTrainPluginEntry = "glint_train_plugin_entry";

}  // namespace glint::edges
