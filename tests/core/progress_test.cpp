// The progress bar's line: bar, count, rate and the time left or taken.
#include "core/progress.h"

#include <gtest/gtest.h>

namespace glint {
namespace {

TEST(ProgressLine, ShowsTheRateAndTheTimeLeft) {
  // 15 of 50 in 3.6 s: 4.2 per second, the other 35 in 8.4 s.
  EXPECT_EQ(progress_line("fuse", 15, 50, 3.6),
            "fuse [#########                     ]  30.0% (15/50, 4.2/s, 0:08 left)");
  // Slower than one per second: seconds per item; past an hour: h:mm:ss.
  EXPECT_EQ(progress_line("train", 2, 100, 90.0),
            "train [                              ]   2.0% (2/100, 45.0 s each, 1:13:30 left)");
}

TEST(ProgressLine, OnceDoneShowsTheTimeTaken) {
  EXPECT_EQ(progress_line("reconstruct", 300, 300, 61.2),
            "reconstruct [##############################] 100.0% (300/300, 4.9/s, 1:01)");
  // More steps than announced count as all done.
  EXPECT_EQ(progress_line("x", 12, 10, 2.0),
            "x [##############################] 100.0% (10/10, 5.0/s, 0:02)");
}

TEST(ProgressLine, NothingDoneOrNothingToDoHasNoRate) {
  EXPECT_EQ(progress_line("edges", 0, 8, 0.5),
            "edges [                              ]   0.0% (0/8)");
  EXPECT_EQ(progress_line("edges", 0, 0, 0.0),
            "edges [##############################] 100.0% (0/0)");
}

}  // namespace
}  // namespace glint
