// The loadable neural-denoiser module (see denoise/denoise_plugin.h).
#include "denoise/denoise_plugin.h"

#include <exception>

#include "core/error.h"
#include "core/progress.h"

extern "C" int glint_denoise_plugin_entry(glint::denoise::DenoisePluginCall* call) {
  try {
    glint::set_quiet(call->quiet);
    *call->result =
        glint::denoise::denoise_neural(*call->noisy, call->guidance, *call->params, call->stats);
    return 0;
  } catch (const glint::Error& e) {
    call->error_file = e.file();
    call->error_element = e.element();
    call->error_reason = e.reason();
  } catch (const std::exception& e) {
    call->error_file = "denoising";
    call->error_reason = e.what();
  }
  return 1;
}
