#include "core/build_info.h"

#include "core/error.h"
#include "core/resources.h"

namespace glint {
namespace {

// A location for the report: the folder, or the reason none was found.
template <class Find>
std::string located(Find&& find) {
  try {
    return find().string();
  } catch (const Error& e) {
    return e.what();
  }
}

}  // namespace

const BuildInfo& build_info() {
  // GLINT_VERSION and GLINT_BUILT_WITH_* are set for this file alone by src/core/CMakeLists.txt.
  static const BuildInfo info{GLINT_VERSION, GLINT_BUILT_WITH_CUDA != 0, GLINT_BUILT_WITH_MPI != 0};
  return info;
}

std::string describe_build() {
  const BuildInfo& info = build_info();
  return "glint " + info.version + "\n" +
         "CUDA: " + (info.cuda ? "compiled in" : "not compiled in (GLINT_WITH_CUDA=OFF)") + "\n" +
         "MPI: " + (info.mpi ? "compiled in" : "not compiled in (GLINT_WITH_MPI=OFF)") + "\n" +
         "models: " + located(models_directory) + "\n" + "plugins: " + located(plugin_directory) +
         "\n" + "viewer page: " + located(web_directory);
}

}  // namespace glint
