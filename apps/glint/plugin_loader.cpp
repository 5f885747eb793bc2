#include "plugin_loader.h"

#include <dlfcn.h>

#include <cstdlib>

#include "core/error.h"

namespace glint::app {

void* plugin_entry(const char* env_var, const std::string& built_path, const char* symbol) {
  const char* override_path = std::getenv(env_var);
  const std::string path = override_path ? override_path : built_path;
  void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!module)
    throw Error(path, "",
                std::string("cannot load the plugin (set ") + env_var + "): " + dlerror());
  void* entry = dlsym(module, symbol);
  if (!entry) throw Error(path, symbol, "not the expected glint plugin");
  return entry;
}

}  // namespace glint::app
