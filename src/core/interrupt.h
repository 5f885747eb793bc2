#pragma once
// Interruption by SIGINT / SIGTERM without leaving anything behind.
//
// The glint executable calls install_interrupt_handlers() once. A signal then only sets a flag;
// long jobs poll it (ProgressBar::advance does at every step, whether the bar is shown or not;
// the render loop at every frame; the commits of AtomicFile, LAS files and staged output
// folders before they rename) and throw Interrupted, whose unwinding removes every temporary
// output (AtomicFile, ".partial-<pid>" folders, temporary tile folders are all RAII). main()
// turns it into exit status 128 + signal (130 for SIGINT, 143 for SIGTERM). A second signal ends
// the process at once (the default action). Without install_interrupt_handlers() (the library in
// another program, Python) the flag is never set and nothing changes.
#include <atomic>
#include <exception>

namespace glint {

// Thrown by throw_if_interrupted(); deliberately not a glint::Error, so that code translating
// errors (adding a file name, a rank) lets it pass unchanged.
class Interrupted : public std::exception {
 public:
  explicit Interrupted(int signal_number) : signal_(signal_number) {}
  int signal_number() const noexcept { return signal_; }
  // 128 + the signal's number, the shell's convention.
  int exit_status() const noexcept { return 128 + signal_; }
  const char* what() const noexcept override;

 private:
  int signal_;
};

// Routes SIGINT and SIGTERM to the flag (each signal once: the handler restores the default
// action, so a second Ctrl-C ends the process without clean-up).
void install_interrupt_handlers();

// The signal that arrived, 0 when none did.
int interrupt_signal() noexcept;

// The flag the signal handler sets. A loadable module has its own copy of this file; it polls the
// host's flag after follow_interrupt_flag(host's interrupt_flag()) (core/plugin_call.h).
const std::atomic<int>* interrupt_flag() noexcept;
void follow_interrupt_flag(const std::atomic<int>* flag) noexcept;

// Throws Interrupted when a signal arrived. Cheap (one relaxed atomic load).
void throw_if_interrupted();

// For tests: as if `signal_number` had arrived (0 clears it).
void set_interrupt_signal_for_testing(int signal_number) noexcept;

}  // namespace glint
