#include "core/fast_exp.h"

#include <gtest/gtest.h>

#include <cmath>

namespace glint {
namespace {

TEST(FastExp, MatchesExpToFloatPrecisionDownToTheSmallestNormalFloat) {
  double worst = 0;
  for (float x = 0; x > -87.0f; x -= 0.0037f) {
    const double exact = std::exp(double(x));
    worst = std::max(worst, std::fabs(double(exp_nonpositive(x)) - exact) / exact);
  }
  EXPECT_LT(worst, 3e-7);
  EXPECT_EQ(exp_nonpositive(0.0f), 1.0f);
}

TEST(FastExp, FlushesToZeroBelowTheNormalFloats) {
  for (const float x : {-88.0f, -100.0f, -1e3f, -1e5f, -2e6f})
    EXPECT_EQ(exp_nonpositive(x), 0.0f) << x;
}

}  // namespace
}  // namespace glint
