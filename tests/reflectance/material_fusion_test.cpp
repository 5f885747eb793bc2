#include "reflectance/material_fusion.h"

#include <gtest/gtest.h>

#include <cmath>

namespace glint::reflectance {
namespace {

TEST(MaterialFusion, IsThePlainMeanUntilTheDivisorClamps) {
  ClampedRunningMean<2> mean(4);
  EXPECT_TRUE(mean.empty());
  for (float v : {1.0f, 2.0f, 3.0f, 4.0f}) mean.add(Eigen::Vector2f(v, -v));
  EXPECT_FLOAT_EQ(mean.mean().x(), 2.5f);
  EXPECT_FLOAT_EQ(mean.mean().y(), -2.5f);
  // Clamped: the fifth estimate enters with weight 1/4, not 1/5.
  mean.add(Eigen::Vector2f(10.0f, 0.0f));
  EXPECT_FLOAT_EQ(mean.mean().x(), 2.5f + (10.0f - 2.5f) / 4);
  EXPECT_EQ(mean.count(), 4);
}

TEST(MaterialFusion, ForgetsAnOldValueGeometrically) {
  // After a change of the estimates the fused value follows with time constant max_divisor.
  ClampedRunningMean<1> mean(60);
  for (int i = 0; i < 200; ++i) mean.add(Eigen::Matrix<float, 1, 1>(0.0f));
  for (int i = 0; i < 60; ++i) mean.add(Eigen::Matrix<float, 1, 1>(1.0f));
  EXPECT_NEAR(mean.mean()[0], 1.0 - std::pow(1.0 - 1.0 / 60, 60), 1e-5);
}

TEST(MaterialFusion, WeightedMeanIsTheWeightedAverageWithThePastDecayed) {
  WeightedRunningMean<1> mean(60);
  EXPECT_TRUE(mean.empty());
  mean.add(Eigen::Matrix<float, 1, 1>(2.0f), 1.0f);
  EXPECT_FLOAT_EQ(mean.mean()[0], 2.0f);
  // A fit explaining 95 % (weight 19) against one explaining 35 % (weight 0.54) before it.
  mean.add(Eigen::Matrix<float, 1, 1>(10.0f), 19.0f);
  const float retained = 1.0f - 1.0f / 60;
  EXPECT_FLOAT_EQ(mean.mean()[0], (retained * 2.0f + 19.0f * 10.0f) / (retained + 19.0f));
  // Estimates without weight leave it unchanged.
  mean.add(Eigen::Matrix<float, 1, 1>(-5.0f), 0.0f);
  mean.add(Eigen::Matrix<float, 1, 1>(-5.0f), std::nanf(""));
  EXPECT_FLOAT_EQ(mean.mean()[0], (retained * 2.0f + 19.0f * 10.0f) / (retained + 19.0f));
  EXPECT_EQ(mean.count(), 2);
}

TEST(MaterialFusion, WeightedMeanWithUnitWeightsKeepsANewEstimatesShareAtTheClamp) {
  // Like the clamped divisor: after many estimates each new one enters with share 1/60.
  WeightedRunningMean<1> mean(60);
  for (int i = 0; i < 2000; ++i) mean.add(Eigen::Matrix<float, 1, 1>(0.0f), 1.0f);
  EXPECT_NEAR(mean.weight_sum(), 60.0f, 1e-2f);
  mean.add(Eigen::Matrix<float, 1, 1>(1.0f), 1.0f);
  EXPECT_NEAR(mean.mean()[0], 1.0f / 60, 1e-5f);
}

}  // namespace
}  // namespace glint::reflectance
