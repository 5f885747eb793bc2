// The loadable training module (see edges/train_plugin.h).
#include "edges/train_plugin.h"

#include <exception>

#include "core/error.h"
#include "core/progress.h"

extern "C" int glint_train_plugin_entry(glint::edges::TrainPluginCall* call) {
  try {
    glint::set_quiet(call->quiet);
    *call->result = glint::edges::train_model(*call->data, *call->config, *call->params);
    return 0;
  } catch (const glint::Error& e) {
    call->error_file = e.file();
    call->error_element = e.element();
    call->error_reason = e.reason();
  } catch (const std::exception& e) {
    call->error_file = "training";
    call->error_reason = e.what();
  }
  return 1;
}
