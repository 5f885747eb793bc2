// Normal maps: edge-aware smoothing of ray-cast normals.
#include "fusion/depth_maps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace glint::fusion {
namespace {

const Intrinsics kCamera{64, 48, 50.0, 50.0, 31.5, 23.5};

// A ridge z = 1 + |x| seen from the origin: two faces meeting at 90 degrees along x = 0.
struct Ridge {
  ImageF depth_m{kCamera.width, kCamera.height, 1};
  ImageF points{kCamera.width, kCamera.height, 3};
  ImageF normals{kCamera.width, kCamera.height, 3};
  ImageF true_normals{kCamera.width, kCamera.height, 3};
};

Ridge noisy_ridge() {
  Ridge ridge;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(-0.15f, 0.15f);
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      const Eigen::Vector3d ray = kCamera.ray(x, y);
      const double z = 1.0 / (1.0 - std::abs(ray.x()));
      const Eigen::Vector3f point = (ray * z).cast<float>();
      const Eigen::Vector3f face =
          Eigen::Vector3f(point.x() > 0 ? 1.0f : -1.0f, 0.0f, -1.0f).normalized();
      const Eigen::Vector3f measured =
          (face + Eigen::Vector3f(noise(rng), noise(rng), noise(rng))).normalized();
      ridge.depth_m.at(x, y, 0) = float(z);
      for (int c = 0; c < 3; ++c) {
        ridge.points.at(x, y, c) = point[c];
        ridge.true_normals.at(x, y, c) = face[c];
        ridge.normals.at(x, y, c) = measured[c];
      }
    }
  return ridge;
}

float angle_deg(const ImageF& a, const ImageF& b, int x, int y) {
  const Eigen::Vector3f u(a.at(x, y, 0), a.at(x, y, 1), a.at(x, y, 2));
  const Eigen::Vector3f v(b.at(x, y, 0), b.at(x, y, 1), b.at(x, y, 2));
  return std::acos(std::clamp(u.dot(v), -1.0f, 1.0f)) * 180.0f / float(M_PI);
}

TEST(SmoothNormals, NoiseIsAveragedWithinEachFaceButNotAcrossTheEdge) {
  Ridge ridge = noisy_ridge();
  const int hole_x = 10, hole_y = 20;
  for (int c = 0; c < 3; ++c) ridge.normals.at(hole_x, hole_y, c) = NAN;
  const ImageF smoothed = smooth_normals(ridge.points, ridge.normals, ridge.depth_m, kCamera, 0.1f);
  double before = 0, after = 0;
  float worst_beside_edge = 0;
  int count = 0;
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      if (x == hole_x && y == hole_y) continue;
      before += angle_deg(ridge.normals, ridge.true_normals, x, y);
      after += angle_deg(smoothed, ridge.true_normals, x, y);
      ++count;
      // The ridge runs between columns 31 and 32 (cx = 31.5).
      if (x == 31 || x == 32)
        worst_beside_edge =
            std::max(worst_beside_edge, angle_deg(smoothed, ridge.true_normals, x, y));
    }
  EXPECT_LT(after / count, 0.4 * before / count) << before / count << " -> " << after / count;
  // Averaging across the 90-degree edge would tilt these by tens of degrees.
  EXPECT_LT(worst_beside_edge, 8.0f);
  EXPECT_TRUE(std::isnan(smoothed.at(hole_x, hole_y, 0)));
}

TEST(SmoothNormals, ExactNormalsOfAPlaneStayExact) {
  Ridge ridge = noisy_ridge();
  const ImageF smoothed =
      smooth_normals(ridge.points, ridge.true_normals, ridge.depth_m, kCamera, 0.1f);
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x)
      ASSERT_LT(angle_deg(smoothed, ridge.true_normals, x, y), 0.05f) << x << ", " << y;
}

}  // namespace
}  // namespace glint::fusion
