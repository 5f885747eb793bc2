#pragma once
// Opens one of glint's loadable modules (the libtorch parts, kept out of the executable's
// start-up) and finds its entry point.
#include <string>

namespace glint::app {

// The module at $`env_var`, else at `built_path`; returns the address of `symbol`. Modules are
// never closed (libtorch does not support being unloaded). Failures -> glint::Error naming the
// module and the variable that overrides it.
void* plugin_entry(const char* env_var, const std::string& built_path, const char* symbol);

}  // namespace glint::app
