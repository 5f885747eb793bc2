// SIGINT / SIGTERM stop long loops at their next check with glint::Interrupted, which carries
// the shell's exit status (130, 143). The end-to-end behaviour of the glint commands (nothing
// left behind) is tests/cli/interrupt_test.py's.
#include "core/interrupt.h"

#include <gtest/gtest.h>

#include <csignal>

#include "core/parallel.h"
#include "core/plugin_call.h"
#include "core/progress.h"

namespace glint {
namespace {

// Clears the flag whatever a test did.
class InterruptTest : public ::testing::Test {
 protected:
  void TearDown() override { set_interrupt_signal_for_testing(0); }
};

TEST_F(InterruptTest, JobsRunWhileNoSignalArrived) {
  ProgressBar progress("test", 10);
  EXPECT_NO_THROW(progress.advance());
  EXPECT_NO_THROW(throw_if_interrupted());
}

TEST_F(InterruptTest, ProgressStepsStopOnceASignalArrived) {
  ProgressBar progress("test", 1000);  // silent here (stderr is no terminal): still checks
  std::atomic<int> steps{0};
  set_interrupt_signal_for_testing(SIGINT);
  try {
    parallel_for(1000, [&](std::size_t) {
      progress.advance();
      ++steps;
    });
    FAIL() << "the loop did not stop";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.signal_number(), SIGINT);
    EXPECT_EQ(e.exit_status(), 130);
    EXPECT_STREQ(e.what(), "interrupted by SIGINT; unfinished outputs removed");
  }
  EXPECT_EQ(steps.load(), 0);
}

TEST_F(InterruptTest, SigtermGivesStatus143) {
  set_interrupt_signal_for_testing(SIGTERM);
  try {
    throw_if_interrupted();
    FAIL() << "no Interrupted";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.exit_status(), 143);
  }
}

// A loadable module polls the flag its host hands it (its own copy of the flag is never set) and
// returns the signal, which the host throws again as Interrupted rather than as an error.
TEST_F(InterruptTest, APluginFollowsTheHostFlagAndHandsTheSignalBack) {
  std::atomic<int> host_flag{0};
  PluginHostState host;
  host.interrupt_flag = &host_flag;
  PluginFailure failure;
  int steps = 0;
  const int status = run_in_plugin(host, failure, "test loop", [&] {
    ProgressBar progress("test", 100);
    for (; steps < 100; ++steps) {
      if (steps == 10) host_flag.store(SIGTERM);
      progress.advance();
    }
  });
  follow_interrupt_flag(nullptr);  // back to this copy's own flag
  EXPECT_EQ(status, 1);
  EXPECT_EQ(steps, 10);
  EXPECT_EQ(interrupt_signal(), 0);
  try {
    failure.rethrow();
    FAIL() << "no Interrupted";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.exit_status(), 143);
  }
}

TEST_F(InterruptTest, TheHandlerOnlySetsTheFlagAndRunsOnce) {
  install_interrupt_handlers();
  std::raise(SIGINT);  // the process goes on
  EXPECT_EQ(interrupt_signal(), SIGINT);
  EXPECT_THROW(throw_if_interrupted(), Interrupted);
  // The handler restored the default action: leave it so for SIGINT, and SIGTERM's too.
  struct sigaction action = {};
  sigaction(SIGINT, nullptr, &action);
  EXPECT_EQ(action.sa_handler, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

}  // namespace
}  // namespace glint
