#include "edges/covariance_baseline.h"

#include <gtest/gtest.h>

#include <random>

namespace glint::edges {
namespace {

TEST(CovarianceBaseline, PlaneIsFlatAndCreaseIsEdge) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  PointCloud cloud;  // an L-shaped fold: floor z = 0 and wall y = 0
  for (int i = 0; i < 4000; ++i) cloud.push_back(u(rng), u(rng), 0.f);
  for (int i = 0; i < 4000; ++i) cloud.push_back(u(rng), 0.f, u(rng));
  cloud.push_back(0.5f, 0.f, 0.f);   // on the crease
  cloud.push_back(0.5f, 0.5f, 0.f);  // in the middle of the floor
  const std::vector<float> variation = surface_variation(cloud, 16);
  EXPECT_GT(variation[cloud.size() - 2], 0.05f);
  EXPECT_LT(variation[cloud.size() - 1], 1e-6f);
  const auto labels = classify_covariance_baseline(cloud);
  EXPECT_EQ(labels[cloud.size() - 2], 1);
  EXPECT_EQ(labels[cloud.size() - 1], 0);
}

}  // namespace
}  // namespace glint::edges
