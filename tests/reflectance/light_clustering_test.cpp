#include "reflectance/light_clustering.h"

#include <gtest/gtest.h>

#include <random>

namespace glint::reflectance {
namespace {

std::vector<LightSample> blob(const Eigen::Vector3d& centre, double spread, int count,
                              const Eigen::Vector3f& radiance, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, spread);
  std::vector<LightSample> samples;
  for (int i = 0; i < count; ++i) {
    LightSample s;
    s.position = centre + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    s.radiance = radiance;
    samples.push_back(s);
  }
  return samples;
}

TEST(LightClustering, MeanShiftFindsTwoLampsAndTheirWeights) {
  std::mt19937 rng(5);
  auto samples = blob({0, 2.5, 0}, 0.02, 300, {5, 5, 4}, rng);
  const auto second = blob({1.5, 2.4, -1}, 0.03, 120, {2, 3, 4}, rng);
  samples.insert(samples.end(), second.begin(), second.end());
  const auto clusters = mean_shift(samples);
  ASSERT_EQ(clusters.size(), 2u);
  EXPECT_LT((clusters[0].position - Eigen::Vector3d(0, 2.5, 0)).norm(), 0.01);
  EXPECT_LT((clusters[1].position - Eigen::Vector3d(1.5, 2.4, -1)).norm(), 0.01);
  EXPECT_DOUBLE_EQ(clusters[0].weight, 300);
  EXPECT_DOUBLE_EQ(clusters[1].weight, 120);
  EXPECT_TRUE(clusters[1].radiance.isApprox(Eigen::Vector3f(2, 3, 4)));
  EXPECT_TRUE(mean_shift({}).empty());
}

TEST(LightClustering, FusionKeepsLightsSeenInEnoughFrames) {
  LightFuser fuser({0.3, 3});
  std::mt19937 rng(9);
  std::normal_distribution<double> jitter(0.0, 0.01);
  for (int frame = 0; frame < 5; ++frame) {
    std::vector<LightSample> candidates(1);
    candidates[0].position = Eigen::Vector3d(0, 2.5, 0) + Eigen::Vector3d(jitter(rng), 0, 0);
    candidates[0].weight = 50;
    if (frame == 2) {  // a specular highlight seen once
      LightSample glare;
      glare.position = {2, 0, 1};
      candidates.push_back(glare);
    }
    fuser.add_frame(candidates);
  }
  const auto lights = fuser.lights();
  ASSERT_EQ(lights.size(), 1u);
  EXPECT_EQ(lights[0].frames, 5);
  EXPECT_LT((lights[0].estimate.position - Eigen::Vector3d(0, 2.5, 0)).norm(), 0.02);
}

}  // namespace
}  // namespace glint::reflectance
