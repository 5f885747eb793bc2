#include "geometry/kdtree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/error.h"

namespace glint::geometry {
namespace {

PointCloud random_cloud(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  PointCloud cloud;
  for (std::size_t i = 0; i < n; ++i) cloud.push_back(u(rng), u(rng), u(rng));
  return cloud;
}

TEST(KdTree, MatchesBruteForceAndIsSorted) {
  const PointCloud cloud = random_cloud(2000, 3);
  KdTree tree(cloud);
  const int k = 20;
  const KnnResult result = tree.knn_all(k);
  for (std::size_t i = 0; i < cloud.size(); i += 97) {
    std::vector<std::pair<float, std::uint32_t>> all;
    for (std::size_t j = 0; j < cloud.size(); ++j) {
      const float dx = cloud.x[j] - cloud.x[i], dy = cloud.y[j] - cloud.y[i],
                  dz = cloud.z[j] - cloud.z[i];
      all.push_back({dx * dx + dy * dy + dz * dz, std::uint32_t(j)});
    }
    std::sort(all.begin(), all.end());
    EXPECT_EQ(result.indices[i * k], i);  // the point itself comes first
    for (int j = 0; j < k; ++j) {
      EXPECT_FLOAT_EQ(result.squared_distances[i * k + j], all[j].first);
      if (j > 0) {
        EXPECT_LE(result.squared_distances[i * k + j - 1], result.squared_distances[i * k + j]);
      }
    }
  }
}

TEST(KdTree, RejectsKLargerThanCloud) {
  const PointCloud cloud = random_cloud(5, 1);
  KdTree tree(cloud);
  EXPECT_THROW(tree.knn_all(6), glint::Error);
  EXPECT_THROW(tree.knn_all(0), glint::Error);
}

}  // namespace
}  // namespace glint::geometry
