#pragma once
// Calls into glint's loadable modules (the libtorch parts). A module links its own copy of
// glint_core, so the process-wide switches it reads (the progress-bar switch, the interrupt flag)
// are not the host's: the call carries the host's state in a PluginHostState and the module
// follows it. Exceptions must not cross the module boundary: the module stores a failure's parts
// (or the signal that interrupted it) in a PluginFailure and returns 1, and the host throws them
// again as a glint::Error (or as Interrupted).
#include <atomic>
#include <exception>
#include <string>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/progress.h"

namespace glint {

// Filled in by the host when it builds the call (the defaults read the host's copies).
struct PluginHostState {
  bool quiet = is_quiet();
  const std::atomic<int>* interrupt_flag = glint::interrupt_flag();
};

struct PluginFailure {
  std::string file, element, reason;
  int interrupt_signal = 0;  // non-zero when a signal, not an error, stopped the module

  [[noreturn]] void rethrow() const {
    if (interrupt_signal != 0) throw Interrupted(interrupt_signal);
    throw Error(file, element, reason);
  }
};

// Module side: adopts the host's state, runs `body`, returns 0, or 1 with the failure recorded
// (`what` names the work for exceptions that are not glint::Error).
template <class Body>
int run_in_plugin(const PluginHostState& host, PluginFailure& failure, const char* what,
                  Body&& body) {
  set_quiet(host.quiet);
  follow_interrupt_flag(host.interrupt_flag);
  try {
    body();
    return 0;
  } catch (const Interrupted& e) {
    failure.interrupt_signal = e.signal_number();
  } catch (const Error& e) {
    failure = {e.file(), e.element(), e.reason()};
  } catch (const std::exception& e) {
    failure = {what, "", e.what()};
  }
  return 1;
}

}  // namespace glint
