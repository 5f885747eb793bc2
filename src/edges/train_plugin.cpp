// The loadable training module (see edges/train_plugin.h).
#include "edges/train_plugin.h"

#include "core/plugin_call.h"

extern "C" int glint_train_plugin_entry(glint::edges::TrainPluginCall* call) {
  return glint::run_in_plugin(call->host, call->failure, "training", [call] {
    *call->result = glint::edges::train_model(*call->data, *call->config, *call->params);
  });
}
