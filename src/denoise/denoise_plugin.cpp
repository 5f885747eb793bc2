// The loadable neural-denoiser module (see denoise/denoise_plugin.h).
#include "denoise/denoise_plugin.h"

#include "core/plugin_call.h"

extern "C" int glint_denoise_plugin_entry(glint::denoise::DenoisePluginCall* call) {
  return glint::run_in_plugin(call->host, call->failure, "denoising", [call] {
    *call->result =
        glint::denoise::denoise_neural(*call->noisy, call->guidance, *call->params, call->stats);
  });
}
