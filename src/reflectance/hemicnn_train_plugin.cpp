// The loadable HemiCNN training module (see reflectance/hemicnn_train_plugin.h).
#include "reflectance/hemicnn_train_plugin.h"

#include "core/plugin_call.h"

extern "C" int glint_hemicnn_plugin_entry(glint::reflectance::HemiCnnPluginCall* call) {
  return glint::run_in_plugin(call->host, call->failure, "HemiCNN training", [call] {
    *call->result = glint::reflectance::train_hemicnn(*call->data, *call->config, *call->params);
  });
}
