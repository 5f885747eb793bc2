// Ray casting an analytic TSDF: depth, normals and colour of a sphere seen head-on, the same
// found from a depth hint, and the normals at its silhouette against a wall.
#include "fusion/raycast.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <utility>

#include "core/error.h"
#include "fusion_test_support.h"

namespace glint::fusion {
namespace {

const Intrinsics kCamera{40, 30, 40.0, 40.0, 19.5, 14.5};
const Eigen::Vector3d kCentre(0, 0, 1.0);  // of the sphere
constexpr double kRadius = 0.3;

// A 1 cm TSDF of `sdf` within extent_m of the origin, 4 cm around its zero level.
std::unique_ptr<TsdfVolume> analytic_volume(
    const std::function<double(const Eigen::Vector3d&)>& sdf, double extent_m) {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.block_capacity = 40000;
  auto volume = std::make_unique<TsdfVolume>(params);
  test::fill_analytic(*volume, sdf, extent_m, 0.04);
  return volume;
}

double sphere(const Eigen::Vector3d& p) { return (p - kCentre).norm() - kRadius; }

TEST(Raycast, SphereDepthAndNormalsMatchTheAnalyticSurface) {
  const auto volume = analytic_volume(sphere, 1.4);
  const Intrinsics& camera = kCamera;
  const Eigen::Vector3d& centre = kCentre;
  const double radius = kRadius;
  const SurfaceView view = raycast(*volume, camera, Pose::Identity(), {.colour = true});
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
  EXPECT_EQ(view.depth_m.at(0, 0, 0), 0.0f);                               // the corner ray misses
  EXPECT_TRUE(raycast(*volume, camera, Pose::Identity()).colour.empty());  // unless asked
}

// First intersection depth of pixel (x, y)'s ray with the sphere, or 0 where it misses or grazes.
double sphere_depth(int x, int y) {
  const Eigen::Vector3d ray = kCamera.ray(x, y);
  const double a = ray.squaredNorm(), b = -2 * ray.dot(kCentre),
               c = kCentre.squaredNorm() - kRadius * kRadius;
  const double discriminant = b * b - 4 * a * c;
  return discriminant < 0.05 ? 0 : (-b - std::sqrt(discriminant)) / (2 * a);
}

// A depth hint (the frame just fused from this pose) 5 mm off the surface: the rays march from
// just in front of it and find the sphere; pixels without a hint march as before.
TEST(Raycast, ADepthHintFindsTheSurfaceNearIt) {
  const auto volume = analytic_volume(sphere, 1.4);
  const SurfaceView marched = raycast(*volume, kCamera, Pose::Identity());
  ImageF hint = marched.depth_m;
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      float& d = hint.at(x, y, 0);
      d = (x + 3 * y) % 7 == 0 || !(d > 0) ? 0.0f : d + 0.005f * float((x + y) % 3 - 1);
    }
  const SurfaceView hinted = raycast(*volume, kCamera, Pose::Identity(), {.depth_hint = &hint});
  int hinted_hits = 0;
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      const float depth = hinted.depth_m.at(x, y, 0);
      if (!(hint.at(x, y, 0) > 0)) {
        EXPECT_EQ(depth, marched.depth_m.at(x, y, 0)) << x << "," << y;
        continue;
      }
      if (sphere_depth(x, y) == 0) continue;
      EXPECT_NEAR(depth, sphere_depth(x, y), 0.002) << x << "," << y;
      ++hinted_hits;
    }
  EXPECT_GT(hinted_hits, 150);
  // Casting only the hinted pixels (the tracking model): the same depths there, none elsewhere.
  const SurfaceView hinted_only = raycast(*volume, kCamera, Pose::Identity(),
                                          {.depth_hint = &hint, .hinted_pixels_only = true});
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x)
      EXPECT_EQ(hinted_only.depth_m.at(x, y, 0),
                hint.at(x, y, 0) > 0 ? hinted.depth_m.at(x, y, 0) : 0.0f)
          << x << "," << y;
}

// A hint behind a surface (one the frame saw through, e.g. an object since moved away): the ray
// marches from in front of the hinted surface and finds it, not the first along the ray; a hint
// of another size is an error.
TEST(Raycast, ADepthHintBehindASurfaceFindsTheHintedOne) {
  constexpr double kWall = 1.6;
  const auto volume = analytic_volume(
      [](const Eigen::Vector3d& p) { return std::min(sphere(p), kWall - p.z()); }, 1.8);
  const int x = kCamera.width / 2, y = kCamera.height / 2;
  ImageF hint(kCamera.width, kCamera.height, 1);
  hint.at(x, y, 0) = float(kWall);
  const SurfaceView view = raycast(*volume, kCamera, Pose::Identity(), {.depth_hint = &hint});
  EXPECT_NEAR(view.depth_m.at(x, y, 0), kWall, 0.002);
  EXPECT_NEAR(view.depth_m.at(x + 1, y, 0), sphere_depth(x + 1, y), 0.002);  // no hint there
  // A hint 2.5 voxels behind the wall (depth noise): the first start, two voxels in front of
  // it, lies behind the wall; the band's front edge is in front of it, and the wall is found,
  // not the sphere.
  hint.at(x, y, 0) = float(kWall + 0.025);
  EXPECT_NEAR(
      raycast(*volume, kCamera, Pose::Identity(), {.depth_hint = &hint}).depth_m.at(x, y, 0), kWall,
      0.002);
  const ImageF wrong(kCamera.width / 2, kCamera.height, 1);
  EXPECT_THROW(raycast(*volume, kCamera, Pose::Identity(), {.depth_hint = &wrong}), Error);
}

TEST(Raycast, RaysCrossMetresOfEmptySpaceToAFarWall) {
  // A wall 3 m away, and a block of free space 0.24-0.32 m in front of the camera: it projects
  // over a third of the image, so those rays start there and cross 2.7 m of empty blocks.
  constexpr double kWall = 3.0;
  const auto volume = analytic_volume([](const Eigen::Vector3d& p) { return kWall - p.z(); }, 3.2);
  // And one across the near plane (z = 0.1 m) beside the camera: only its part beyond the plane
  // counts for the tiles' depth ranges.
  for (const Eigen::Vector3i& b : {Eigen::Vector3i(0, 0, 3), Eigen::Vector3i(3, 0, 1)}) {
    const int near_block = volume->allocate(b);
    ASSERT_GE(near_block, 0);
    std::fill_n(volume->sdf_m(near_block), kVoxelsPerBlock, 0.04f);
    std::fill_n(volume->weight(near_block), kVoxelsPerBlock, std::uint8_t{1});
  }
  const SurfaceView view = raycast(*volume, kCamera, Pose::Identity());
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x)
      ASSERT_NEAR(view.depth_m.at(x, y, 0), kWall, 0.002) << x << "," << y;
}

TEST(Raycast, RaysStrideThroughUnobservedVoxelsAndStepBackToTheSurface) {
  // A wall 1.003 m away behind 48 cm of allocated blocks no frame observed, and of its band in
  // front only the last 2.8 cm observed: shorter than a stride through unobserved voxels (3 cm),
  // so strides land behind the wall and must step back to find it.
  constexpr double kWall = 1.003;
  const auto volume = analytic_volume([](const Eigen::Vector3d& p) { return kWall - p.z(); }, 1.2);
  for (int z = 5; z <= 10; ++z)
    for (int y = -4; y <= 3; ++y)
      for (int x = -4; x <= 3; ++x) ASSERT_GE(volume->allocate({x, y, z}), 0);
  for (std::size_t block = 0; block < volume->block_count(); ++block)
    for (int v = 0; v < kVoxelsPerBlock; ++v)
      if (observed(volume->sdf_m(int(block))[v]) && volume->sdf_m(int(block))[v] > 0.025f) {
        volume->sdf_m(int(block))[v] = kUnobservedSdf;
        volume->weight(int(block))[v] = 0;
      }
  const SurfaceView view = raycast(*volume, kCamera, Pose::Identity());
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x)
      ASSERT_NEAR(view.depth_m.at(x, y, 0), kWall, 0.002) << x << "," << y;
}

TEST(Raycast, GradientNormalsHoldAtSilhouettes) {
  // The sphere in front of a wall: at its silhouette the neighbouring pixels lie on the wall, so
  // the points' cross product is no normal of either; the TSDF's gradient is the sphere's own.
  const double wall_z = 1.6;
  const auto volume = analytic_volume(
      [&](const Eigen::Vector3d& p) { return std::min(sphere(p), wall_z - p.z()); }, 1.8);
  const Intrinsics& camera = kCamera;
  const SurfaceView points = raycast(*volume, camera, Pose::Identity());
  const SurfaceView gradient =
      raycast(*volume, camera, Pose::Identity(), {.normals = RaycastNormals::from_gradient});
  const auto normal = [](const SurfaceView& view, int x, int y) {
    return Eigen::Vector3d(view.normals.at(x, y, 0), view.normals.at(x, y, 1),
                           view.normals.at(x, y, 2));
  };
  int silhouette = 0;
  double worst_points = 1;  // the points' normals at the silhouette
  for (int y = 1; y < camera.height - 1; ++y)
    for (int x = 1; x < camera.width - 1; ++x) {
      const double depth = points.depth_m.at(x, y, 0);
      if (!(depth > 0) || depth > wall_z - 0.05) continue;  // the sphere's pixels only
      bool beside_wall = false;
      for (const auto& [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}})
        beside_wall = beside_wall || points.depth_m.at(x + dx, y + dy, 0) > wall_z - 0.05;
      EXPECT_EQ(gradient.depth_m.at(x, y, 0), depth) << "only the normals differ";
      const Eigen::Vector3d p = depth * camera.ray(x, y);
      const Eigen::Vector3d truth = (p - kCentre).normalized();
      EXPECT_GT(normal(gradient, x, y).dot(truth), 0.95) << x << "," << y;
      if (!beside_wall) continue;
      ++silhouette;
      worst_points = std::min(worst_points, normal(points, x, y).dot(truth));
    }
  EXPECT_GT(silhouette, 20);
  EXPECT_LT(worst_points, 0.8) << "the case the gradient is for";
}

}  // namespace
}  // namespace glint::fusion
