#pragma once
// Calls into glint's loadable modules (the libtorch parts) must not let exceptions cross the
// module boundary: the module stores a failure's parts in a PluginFailure and returns 1, and
// the host throws them again as a glint::Error.
#include <exception>
#include <string>

#include "core/error.h"

namespace glint {

struct PluginFailure {
  std::string file, element, reason;

  [[noreturn]] void rethrow() const { throw Error(file, element, reason); }
};

// Module side: runs `body`, returns 0, or 1 with the failure recorded (`what` names the work
// for exceptions that are not glint::Error).
template <class Body>
int run_in_plugin(PluginFailure& failure, const char* what, Body&& body) {
  try {
    body();
    return 0;
  } catch (const Error& e) {
    failure = {e.file(), e.element(), e.reason()};
  } catch (const std::exception& e) {
    failure = {what, "", e.what()};
  }
  return 1;
}

}  // namespace glint
