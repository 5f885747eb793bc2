// The radiance a ray brings back from the surface it hit (reflectance/hit_radiance.h): a wall
// 1 mm in front of a face of the 2 cm observation voxels keeps its observations on that side;
// hits and points interpolated up to a TSDF voxel past the face still read them, grazing rays
// included.
#include "reflectance/hit_radiance.h"

#include <gtest/gtest.h>

#include "fusion/integrate.h"

namespace glint::reflectance {
namespace {

const Intrinsics kCamera{80, 60, 60.0, 60.0, 39.5, 29.5};
constexpr float kWall = 0.999f;  // the wall's depth: 1 mm before the voxel face z = 1
constexpr float kTsdfVoxel = 0.005f;

// A uniformly coloured wall at z = kWall fused once and observed from the origin.
struct ObservedWall {
  fusion::TsdfVolume geometry{[] {
    fusion::VolumeParams params;
    params.voxel_size_m = kTsdfVoxel;
    params.block_capacity = 1 << 12;
    return params;
  }()};
  ObservationGrid grid{ObservationGridParams{.voxel_capacity = 1 << 14}};
  ObservedWall() {
    const ImageF depth(kCamera.width, kCamera.height, 1, kWall);
    const ImageF colour(kCamera.width, kCamera.height, 3, 0.25f);
    fusion::VisibleBlocks blocks;
    fusion::integrate(geometry, depth, colour, kCamera, Pose::Identity(), blocks);
    for (const VisibleVoxel& seen :
         grid.collect(depth, colour, kCamera, Pose::Identity(), 1.0f, geometry, 0))
      if (grid.observation_count(seen.voxel) > 0) observed = seen.voxel;
  }
  int observed = -1;  // a voxel of the wall with an observation
};

TEST(HitRadiance, ReadsTheObservationsAcrossTheNearestVoxelFace) {
  const ObservedWall wall;
  ObservationGrid::BlockCache blocks;
  Eigen::Vector3f radiance;
  ASSERT_GE(wall.observed, 0);
  // At x, y of that voxel's surface point, the middle of the voxel, 1 cm from its side faces.
  const Eigen::Vector3f point = wall.grid.position(wall.observed);
  const auto at = [&](float z) { return Eigen::Vector3f(point.x(), point.y(), z); };
  ASSERT_NEAR(point.z(), kWall, 1e-3f);
  EXPECT_EQ(wall.grid.find(at(kWall)), wall.observed);
  EXPECT_LT(wall.grid.find(at(1.001f)), 0) << "no depth pixel fell past the face";

  // On the wall: its voxel.
  const Eigen::Vector3f steep = Eigen::Vector3f(0.1f, 0, 1).normalized();
  ASSERT_TRUE(hit_radiance(wall.grid, at(kWall), steep, kTsdfVoxel, blocks, radiance));
  EXPECT_FLOAT_EQ(radiance.x(), 0.25f);
  // 2 mm past the wall, 1 mm past the face: a steep ray's step back reaches the wall's voxel...
  ASSERT_TRUE(hit_radiance(wall.grid, at(1.001f), steep, kTsdfVoxel, blocks, radiance));
  EXPECT_FLOAT_EQ(radiance.x(), 0.25f);
  // ...a grazing one's (84 degrees from the normal) stays past the face, and the voxel across
  // it, 1 mm away, has them.
  const Eigen::Vector3f grazing = Eigen::Vector3f(1, 0, 0.1f).normalized();
  ASSERT_TRUE(hit_radiance(wall.grid, at(1.001f), grazing, kTsdfVoxel, blocks, radiance));
  EXPECT_FLOAT_EQ(radiance.x(), 0.25f);
  // 8 mm past the face, beyond a TSDF voxel: not the wall's.
  EXPECT_FALSE(hit_radiance(wall.grid, at(1.008f), grazing, kTsdfVoxel, blocks, radiance));

  // The voxel holding the surface at a point (a re-rendered pixel's): the same faces, no ray.
  EXPECT_EQ(observed_voxel(wall.grid, at(kWall), kTsdfVoxel, blocks), wall.observed);
  EXPECT_EQ(observed_voxel(wall.grid, at(1.001f), kTsdfVoxel, blocks), wall.observed);
  EXPECT_EQ(observed_voxel(wall.grid, at(1.008f), kTsdfVoxel, blocks), -1);
}

}  // namespace
}  // namespace glint::reflectance
