#include "core/interrupt.h"

#include <atomic>
#include <csignal>

namespace glint {
namespace {

// Lock-free, so it may be written from a signal handler.
std::atomic<int> arrived_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
// The flag interrupt_signal() reads: this copy's own, or the host's in a loadable module.
std::atomic<const std::atomic<int>*> polled_flag{&arrived_signal};

extern "C" void on_interrupt_signal(int signal_number) {
  arrived_signal.store(signal_number, std::memory_order_relaxed);
}

}  // namespace

const char* Interrupted::what() const noexcept {
  return signal_ == SIGTERM ? "interrupted by SIGTERM; unfinished outputs removed"
                            : "interrupted by SIGINT; unfinished outputs removed";
}

void install_interrupt_handlers() {
  for (const int signal_number : {SIGINT, SIGTERM}) {
    struct sigaction action = {};
    action.sa_handler = on_interrupt_signal;
    sigemptyset(&action.sa_mask);
    // Interrupted reads and writes restart (the flag is polled, not the calls' errors); the
    // handler runs once, a second signal takes the default action.
    action.sa_flags = SA_RESTART | SA_RESETHAND;
    sigaction(signal_number, &action, nullptr);
  }
}

int interrupt_signal() noexcept {
  return polled_flag.load(std::memory_order_relaxed)->load(std::memory_order_relaxed);
}

const std::atomic<int>* interrupt_flag() noexcept {
  return polled_flag.load(std::memory_order_relaxed);
}

void follow_interrupt_flag(const std::atomic<int>* flag) noexcept {
  polled_flag.store(flag != nullptr ? flag : &arrived_signal, std::memory_order_relaxed);
}

void throw_if_interrupted() {
  const int signal_number = interrupt_signal();
  if (signal_number != 0) throw Interrupted(signal_number);
}

void set_interrupt_signal_for_testing(int signal_number) noexcept {
  arrived_signal.store(signal_number, std::memory_order_relaxed);
}

}  // namespace glint
