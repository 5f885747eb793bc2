// Ray casting an analytic TSDF: depth, normals and colour of a sphere seen head-on.
#include "fusion/raycast.h"

#include <gtest/gtest.h>

#include <cmath>

#include "fusion_test_support.h"

namespace glint::fusion {
namespace {

TEST(Raycast, SphereDepthAndNormalsMatchTheAnalyticSurface) {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.block_capacity = 20000;
  TsdfVolume volume(params);
  const Eigen::Vector3d centre(0, 0, 1.0);
  const double radius = 0.3;
  test::fill_analytic(
      volume, [&](const Eigen::Vector3d& p) { return (p - centre).norm() - radius; }, 1.4, 0.04);
  const Intrinsics camera{40, 30, 40.0, 40.0, 19.5, 14.5};
  const SurfaceView view = raycast(volume, camera, Pose::Identity());
  int hits = 0;
  for (int y = 1; y < camera.height - 1; ++y) {
    for (int x = 1; x < camera.width - 1; ++x) {
      const Eigen::Vector3d ray = camera.ray(x, y);
      // First intersection of t * ray with the sphere.
      const double a = ray.squaredNorm(), b = -2 * ray.dot(centre),
                   c = centre.squaredNorm() - radius * radius;
      const double discriminant = b * b - 4 * a * c;
      const double depth = view.depth_m.at(x, y, 0);
      if (discriminant < 0.05) continue;  // misses or grazes the sphere
      const double t = (-b - std::sqrt(discriminant)) / (2 * a);
      ASSERT_GT(depth, 0) << x << "," << y;
      EXPECT_NEAR(depth, t, 0.002);
      const Eigen::Vector3d normal(view.normals.at(x, y, 0), view.normals.at(x, y, 1),
                                   view.normals.at(x, y, 2));
      if (normal.allFinite()) {
        EXPECT_GT(normal.dot((t * ray - centre).normalized()), 0.98);
      }
      EXPECT_NEAR(view.colour.at(x, y, 1), 0.5, 1e-6);
      ++hits;
    }
  }
  EXPECT_GT(hits, 200);
  EXPECT_EQ(view.depth_m.at(0, 0, 0), 0.0f);  // the corner ray misses
}

}  // namespace
}  // namespace glint::fusion
