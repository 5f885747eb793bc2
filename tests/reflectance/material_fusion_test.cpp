#include "reflectance/material_fusion.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace glint::reflectance
