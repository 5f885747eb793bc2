#include "reflectance/depth_segmentation.h"

#include <gtest/gtest.h>

#include <functional>
#include <set>
#include <utility>

namespace glint::reflectance {
namespace {

const Intrinsics kCamera{128, 96, 100.0, 100.0, 63.5, 47.5};

// A depth image whose pixel (u, v) has depth depth_of(a, b) for the ray (a, b, 1).
ImageF depth_image(const std::function<float(double, double)>& depth_of) {
  ImageF depth(kCamera.width, kCamera.height, 1);
  for (int v = 0; v < kCamera.height; ++v)
    for (int u = 0; u < kCamera.width; ++u) {
      const Eigen::Vector3d ray = kCamera.ray(u, v);
      depth.at(u, v, 0) = depth_of(ray.x(), ray.y());
    }
  return depth;
}

std::set<int> labels_in_columns(const DepthSegmentation& s, int x0, int x1) {
  std::set<int> found;
  for (int y = 10; y < kCamera.height - 10; ++y)
    for (int x = x0; x < x1; ++x) found.insert(s.labels.at(x, y, 0));
  return found;
}

TEST(DepthSegmentation, AConcaveCornerSplitsIntoTwoSegments) {
  // z = 2 - 0.8 |x|: two walls meeting in a valley, the inside of a room corner.
  const auto s = segment_depth(
      depth_image([](double a, double) { return 2 / (1 + 0.8 * std::abs(a)); }), kCamera);
  EXPECT_EQ(s.segment_count, 2);
  const auto left = labels_in_columns(s, 5, 50), right = labels_in_columns(s, 78, 123);
  ASSERT_EQ(left.size(), 1u);
  ASSERT_EQ(right.size(), 1u);
  EXPECT_NE(*left.begin(), *right.begin());
  EXPECT_NE(*left.begin(), 0);
}

TEST(DepthSegmentation, AConvexRidgeStaysOneSegment) {
  // z = 2 + 0.8 |x|: the ridge points at the camera (an object's outer corner).
  const auto s = segment_depth(
      depth_image([](double a, double) { return 2 / (1 - 0.8 * std::abs(a)); }), kCamera);
  EXPECT_EQ(s.segment_count, 1);
  EXPECT_EQ(labels_in_columns(s, 5, 123), std::set<int>{1});
}

TEST(DepthSegmentation, DepthDiscontinuitiesAndHolesSeparate) {
  // Two fronto-parallel planes at 1.5 m and 2.5 m, and a missing-depth stripe in the far one.
  const auto s = segment_depth(depth_image([](double a, double b) -> float {
                                 if (a < 0) return 1.5f;
                                 return b > 0.1 && b < 0.15 ? 0.0f : 2.5f;
                               }),
                               kCamera);
  EXPECT_EQ(s.segment_count, 3);                   // near plane, far plane above and below the hole
  EXPECT_EQ(s.labels.at(63 + 12, 47 + 12, 0), 0);  // the hole stays unlabelled (b = 0.12)
  EXPECT_NE(labels_in_columns(s, 5, 50), labels_in_columns(s, 78, 123));
}

TEST(DepthSegmentation, ASegmenterReusedAcrossFramesAndSizesMatchesAFreshOne) {
  // One segmenter over frames of two sizes (its buffers kept) gives what a fresh call gives.
  const ImageF valley = depth_image([](double a, double) { return 2 / (1 + 0.8 * std::abs(a)); });
  const ImageF steps = depth_image([](double a, double) { return a < 0 ? 1.5f : 2.5f; });
  const Intrinsics half = kCamera.scaled(0.5);
  ImageF small_image(half.width, half.height, 1);
  for (int y = 0; y < half.height; ++y)
    for (int x = 0; x < half.width; ++x) small_image.at(x, y, 0) = valley.at(2 * x, 2 * y, 0);
  const ImageF& small = small_image;
  DepthSegmenter segmenter;
  for (int round = 0; round < 2; ++round)
    for (const auto& [depth, camera] :
         {std::pair{&valley, kCamera}, std::pair{&small, half}, std::pair{&steps, kCamera}}) {
      const DepthSegmentation& reused = segmenter.segment(*depth, camera);
      const DepthSegmentation fresh = segment_depth(*depth, camera);
      ASSERT_EQ(reused.segment_count, fresh.segment_count);
      ASSERT_EQ(reused.labels.width(), depth->width());
      for (int y = 0; y < depth->height(); ++y)
        for (int x = 0; x < depth->width(); ++x) {
          ASSERT_EQ(reused.labels.at(x, y, 0), fresh.labels.at(x, y, 0));
          ASSERT_EQ(reused.edges.at(x, y, 0), fresh.edges.at(x, y, 0));
        }
    }
}

TEST(DepthSegmentation, NoDepthGivesNoSegments) {
  const auto s = segment_depth(ImageF(kCamera.width, kCamera.height, 1, 0.0f), kCamera);
  EXPECT_EQ(s.segment_count, 0);
}

}  // namespace
}  // namespace glint::reflectance
