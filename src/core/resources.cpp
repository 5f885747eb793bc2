#include "core/resources.h"

#include <dlfcn.h>
#include <link.h>

#include <cstdlib>
#include <system_error>

#include "core/error.h"

namespace glint {
namespace fs = std::filesystem;
namespace {

const char* environment(const char* name) {
  const char* value = std::getenv(name);
  return value && *value ? value : nullptr;
}

// The first existing `relative` below candidate_prefixes(); empty when none. `searched`
// collects the paths tried, for the error message.
fs::path find_below_prefixes(const fs::path& relative, std::vector<std::string>& searched) {
  for (const fs::path& prefix : candidate_prefixes()) {
    const fs::path candidate = prefix / relative;
    std::error_code error;
    if (fs::exists(candidate, error)) return candidate;
    searched.push_back(candidate.string());
  }
  return {};
}

std::string join(const std::vector<std::string>& paths) {
  std::string text;
  for (const std::string& path : paths) text += (text.empty() ? "" : ", ") + path;
  return text;
}

fs::path directory_from(const char* variable) {
  const char* value = environment(variable);
  if (!value) return {};
  if (!fs::is_directory(value))
    throw Error(std::string("$") + variable + "=" + value, "", "no such folder");
  return value;
}

}  // namespace

fs::path code_location() {
  // dladdr names the object that holds this function; the executable has no name there (its
  // l_name is empty and dli_fname is argv[0]), so /proc/self/exe names it.
  Dl_info info{};
  link_map* object = nullptr;
  if (dladdr1(reinterpret_cast<void*>(&code_location), &info, reinterpret_cast<void**>(&object),
              RTLD_DL_LINKMAP) &&
      object && object->l_name && object->l_name[0] != '\0') {
    std::error_code error;
    const fs::path resolved = fs::weakly_canonical(object->l_name, error);
    return error ? fs::path(object->l_name) : resolved;
  }
  std::error_code error;
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (error) throw Error("/proc/self/exe", "", "cannot tell where the running program is");
  return executable;
}

std::vector<fs::path> candidate_prefixes() {
  std::vector<fs::path> prefixes;
  fs::path folder = code_location().parent_path();
  for (int level = 1; level <= kMaxPrefixLevels && folder.has_relative_path(); ++level) {
    folder = folder.parent_path();
    prefixes.push_back(folder);
  }
  return prefixes;
}

fs::path models_directory() {
  for (const char* variable : {"GLINT_MODELS_DIR", "GLINT_MODELS"}) {
    if (fs::path folder = directory_from(variable); !folder.empty()) return folder;
  }
  std::vector<std::string> searched;
  const fs::path found = find_below_prefixes(fs::path("share") / "glint" / "models", searched);
  if (found.empty())
    throw Error("", "",
                "no models folder found (set GLINT_MODELS_DIR); searched " + join(searched));
  return found;
}

fs::path web_directory() {
  if (fs::path folder = directory_from("GLINT_WEB_DIR"); !folder.empty()) return folder;
  std::vector<std::string> searched;
  const fs::path found = find_below_prefixes(fs::path("share") / "glint" / "web", searched);
  if (found.empty())
    throw Error("", "", "no viewer page found (set GLINT_WEB_DIR); searched " + join(searched));
  return found;
}

fs::path model_path(const std::string& file_name) {
  const fs::path path = models_directory() / file_name;
  if (!fs::exists(path)) throw Error(path.string(), "", "no such model");
  return path;
}

fs::path plugin_directory() {
  if (fs::path folder = directory_from("GLINT_PLUGIN_DIR"); !folder.empty()) return folder;
  std::vector<std::string> searched;
  const fs::path found = find_below_prefixes(fs::path("lib") / "glint", searched);
  if (found.empty())
    throw Error("", "",
                "no plugin folder found (set GLINT_PLUGIN_DIR); searched " + join(searched));
  return found;
}

fs::path plugin_path(const PluginName& plugin) {
  if (const char* file = environment(plugin.env_var)) return file;
  std::vector<std::string> searched;
  if (const char* folder = environment("GLINT_PLUGIN_DIR")) {
    const fs::path candidate = fs::path(folder) / plugin.file_name;
    if (fs::exists(candidate)) return candidate;
    searched.push_back(candidate.string());
  } else {
    const fs::path found =
        find_below_prefixes(fs::path("lib") / "glint" / plugin.file_name, searched);
    if (!found.empty()) return found;
  }
  throw Error(plugin.file_name, "",
              std::string("plugin not found (set ") + plugin.env_var +
                  " or GLINT_PLUGIN_DIR); searched " + join(searched));
}

void* plugin_entry(const PluginName& plugin, const char* symbol) {
  const std::string path = plugin_path(plugin).string();
  void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!module)
    throw Error(path, "",
                std::string("cannot load the plugin (set ") + plugin.env_var + "): " + dlerror());
  void* entry = dlsym(module, symbol);
  if (!entry) throw Error(path, symbol, "not the expected glint plugin");
  return entry;
}

}  // namespace glint
