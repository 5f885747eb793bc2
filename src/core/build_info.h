#pragma once
// What this build of glint is: its version and the optional parts compiled in (for
// `glint --version`, reports and the Python module).
#include <string>

namespace glint {

struct BuildInfo {
  std::string version;  // the project version, e.g. "0.1.0"
  bool cuda = false;    // configured with GLINT_WITH_CUDA=ON
  bool mpi = false;     // configured with GLINT_WITH_MPI=ON
};

const BuildInfo& build_info();

// The text of `glint --version`: the version, CUDA and MPI compiled in or not, and where the
// models and plugins are found (or why they are not), one item per line.
std::string describe_build();

}  // namespace glint
