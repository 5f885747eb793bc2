#include "reflectance/depth_segmentation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <utility>

namespace glint::reflectance {
namespace {

const Intrinsics kCamera{128, 96, 100.0, 100.0, 63.5, 47.5};
// A Kinect's field of view at the pipeline's half resolution (fx = 585 / 2): neighbours 2 pixels
// apart lie under 2 cm apart at 2.5 m, not far beyond the noise.
const Intrinsics kKinectHalf{128, 96, 292.5, 292.5, 63.5, 47.5};

// A depth image whose pixel (u, v) has depth depth_of(a, b) for the ray (a, b, 1).
ImageF depth_image(const std::function<float(double, double)>& depth_of,
                   const Intrinsics& camera = kCamera) {
  ImageF depth(camera.width, camera.height, 1);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d ray = camera.ray(u, v);
      depth.at(u, v, 0) = depth_of(ray.x(), ray.y());
    }
  return depth;
}

// depth_of's image at kKinectHalf with Gaussian noise of 0.75 sigma(z) (core/camera.h's Kinect
// noise per pixel: the pipeline's 2x2 average would halve independent noise, but a Kinect's is
// correlated over several pixels), seeded.
ImageF noisy_depth_image(const std::function<float(double, double)>& depth_of) {
  ImageF depth = depth_image(depth_of, kKinectHalf);
  std::mt19937 random(7);
  std::normal_distribution<float> unit;
  for (float& z : depth.values()) z += 0.75f * kinect_axial_noise_m(z) * unit(random);
  return depth;
}

// Pixels per label (0 included) in columns [x0, x1) of the rows away from the border.
std::map<int, int> label_areas(const DepthSegmentation& s, int x0, int x1) {
  std::map<int, int> area;
  for (int y = 10; y < kCamera.height - 10; ++y)
    for (int x = x0; x < x1; ++x) ++area[s.labels.at(x, y, 0)];
  return area;
}

int largest_labelled_area(const std::map<int, int>& areas) {
  int largest = 0;
  for (const auto& [label, area] : areas)
    if (label > 0) largest = std::max(largest, area);
  return largest;
}

// The labels (0 included) in those columns.
std::set<int> labels_in_columns(const DepthSegmentation& s, int x0, int x1) {
  std::set<int> found;
  for (const auto& [label, area] : label_areas(s, x0, x1)) found.insert(label);
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

TEST(DepthSegmentation, ANoisyWallStaysOneSegment) {
  // A slanted wall 1.9-3.7 m away: within the noise, whether a neighbour lies in front of the
  // tangent plane says nothing about concavity.
  const ImageF wall = noisy_depth_image([](double a, double) { return 2.5 / (1 + 1.5 * a); });
  const int pixels = (kCamera.width - 20) * (kCamera.height - 20);
  EXPECT_GT(largest_labelled_area(label_areas(segment_depth(wall, kKinectHalf), 10, 118)),
            0.9 * pixels);
  // A fixed 0.5 mm tolerance, as before, shatters it.
  DepthSegmentationParams fixed;
  fixed.convexity_noise_k = 0;
  EXPECT_LT(largest_labelled_area(label_areas(segment_depth(wall, kKinectHalf, fixed), 10, 118)),
            0.5 * pixels);
}

TEST(DepthSegmentation, ANoisyConcaveCornerStillSplits) {
  // The inside of a room corner, as in AConcaveCornerSplitsIntoTwoSegments, 1.2-2 m away.
  const auto s = segment_depth(
      noisy_depth_image([](double a, double) { return 2 / (1 + 3 * std::abs(a)); }), kKinectHalf);
  const auto left = label_areas(s, 10, 54), right = label_areas(s, 74, 118);
  const int side = 44 * (kCamera.height - 20);
  const auto main_label = [](const std::map<int, int>& areas) {
    return std::max_element(areas.begin(), areas.end(),
                            [](const auto& a, const auto& b) { return a.second < b.second; })
        ->first;
  };
  EXPECT_GT(largest_labelled_area(left), 0.8 * side);
  EXPECT_GT(largest_labelled_area(right), 0.8 * side);
  EXPECT_NE(main_label(left), main_label(right));
}

TEST(DepthSegmentation, NoDepthGivesNoSegments) {
  const auto s = segment_depth(ImageF(kCamera.width, kCamera.height, 1, 0.0f), kCamera);
  EXPECT_EQ(s.segment_count, 0);
}

}  // namespace
}  // namespace glint::reflectance
