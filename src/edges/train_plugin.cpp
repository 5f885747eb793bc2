// The loadable training module (see edges/train_plugin.h).
#include "edges/train_plugin.h"

#include "core/plugin_call.h"
#include "core/progress.h"

extern "C" int glint_train_plugin_entry(glint::edges::TrainPluginCall* call) {
  return glint::run_in_plugin(call->failure, "training", [call] {
    glint::set_quiet(call->quiet);
    *call->result = glint::edges::train_model(*call->data, *call->config, *call->params);
  });
}
