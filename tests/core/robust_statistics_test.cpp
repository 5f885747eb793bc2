#include "core/robust_statistics.h"

#include <gtest/gtest.h>

#include <vector>

namespace glint {
namespace {

TEST(RobustStatistics, MedianAndSpreadIgnoreAMinorityOfOutliers) {
  // 1..9: median 5, absolute deviations 0,1,1,2,2,3,3,4,4 -> MAD 2.
  std::vector<float> regular = {5, 1, 9, 3, 7, 2, 8, 4, 6};
  const float median = median_in_place(regular);
  EXPECT_EQ(median, 5.0f);
  EXPECT_FLOAT_EQ(robust_spread_in_place(regular, median), 1.4826f * 2);
  // Replacing the two extremes by outliers leaves both unchanged.
  std::vector<float> outliers = {5, -1e6f, 1e6f, 3, 7, 2, 8, 4, 6};
  EXPECT_EQ(median_in_place(outliers), 5.0f);
  EXPECT_FLOAT_EQ(robust_spread_in_place(outliers, 5.0f), 1.4826f * 2);
  // One value: no spread.
  std::vector<float> one = {0.3f};
  EXPECT_EQ(median_in_place(one), 0.3f);
  EXPECT_EQ(robust_spread_in_place(one, 0.3f), 0.0f);
}

}  // namespace
}  // namespace glint
