#pragma once
// Where glint's installed files are: the shipped models, the viewer's web page and the loadable
// modules (plugins).
// They are found relative to the running glint code, never through a path compiled in, so an
// installed or moved glint works from anywhere:
//   <prefix>/bin/glint                                   the executable
//   <prefix>/lib/glint/<plugin>.so                       the plugins
//   <prefix>/share/glint/models/                         the models
//   <prefix>/share/glint/web/                            the viewer page and its three.js modules
//   <prefix>/lib/python3/dist-packages/glint/<module>.so  the Python extension module
// <prefix> is the nearest of the kMaxPrefixLevels folders above the folder of the file holding
// the running code (the executable, or the shared object glint_core was linked into, such as
// the Python module or a plugin) that holds the wanted file. The build tree has the same layout:
// build/<preset>/share/glint/models, build/<preset>/share/glint/web and build/<preset>/lib/glint.
// Environment variables override each location.
#include <filesystem>
#include <string>
#include <vector>

namespace glint {

// Up to 4 folders up: far enough from lib/python3/dist-packages/glint/ to reach <prefix>.
inline constexpr int kMaxPrefixLevels = 4;

// The file holding the running glint code: /proc/self/exe when glint_core is linked into the
// executable, else the shared object it is linked into. Symbolic links resolved.
std::filesystem::path code_location();

// The folders tried as <prefix>, nearest first: the 1st to kMaxPrefixLevels-th folders above
// code_location()'s folder (for <prefix>/bin/glint: <prefix>, then its parents).
std::vector<std::filesystem::path> candidate_prefixes();

// The models folder: $GLINT_MODELS_DIR, else $GLINT_MODELS, else the first
// <prefix>/share/glint/models of candidate_prefixes() that exists. Throws glint::Error that
// names the variable (when it names no folder) or every folder searched.
std::filesystem::path models_directory();

// A shipped model: models_directory() / file_name. Throws glint::Error naming the path when
// the file is missing.
std::filesystem::path model_path(const std::string& file_name);

// The viewer page's folder (index.html, viewer.js, three/: the three.js modules it imports):
// $GLINT_WEB_DIR, else the first <prefix>/share/glint/web of candidate_prefixes() that exists.
// Throws glint::Error that names the variable (when it names no folder) or every folder searched.
std::filesystem::path web_directory();

// One of glint's loadable modules (the libtorch parts, kept out of the executable's start-up).
// Each module's header names its own (e.g. edges/train_plugin.h).
struct PluginName {
  const char* file_name;  // under lib/glint/, e.g. "edges-train.so"
  const char* env_var;    // names another file instead, e.g. "GLINT_TRAIN_PLUGIN"
};

// The plugin's file: $<env_var>, else $GLINT_PLUGIN_DIR/<file_name>, else the first
// <prefix>/lib/glint/<file_name> of candidate_prefixes() that exists. Throws glint::Error that
// names every place searched and the variables that override them.
std::filesystem::path plugin_path(const PluginName& plugin);

// Opens the plugin (plugin_path) and returns the address of `symbol`. Modules are never closed
// (libtorch does not support being unloaded). Failures -> glint::Error naming the file.
void* plugin_entry(const PluginName& plugin, const char* symbol);

// The plugin folder for reports (`glint --version`): $GLINT_PLUGIN_DIR, else the first
// <prefix>/lib/glint that exists. Throws glint::Error naming the folders searched.
std::filesystem::path plugin_directory();

}  // namespace glint
