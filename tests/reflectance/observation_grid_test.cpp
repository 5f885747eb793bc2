// Observation collection on analytic depth images: surface points and normals from the fused
// TSDF, the visibility test, radiance units, pool exhaustion.
#include "reflectance/observation_grid.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "fusion/integrate.h"
#include "support/error_of.h"

namespace glint::reflectance {
namespace {

const Intrinsics kCamera{80, 60, 60.0, 60.0, 39.5, 29.5};

fusion::VolumeParams geometry_params() {
  fusion::VolumeParams params;
  params.voxel_size_m = 0.005;
  params.block_capacity = 1 << 12;
  return params;
}

ObservationGridParams grid_params() {
  ObservationGridParams params;
  params.voxel_capacity = 1 << 14;
  return params;
}

// A wall at z = wall_m seen from the origin, uniformly coloured.
struct Wall {
  ImageF depth{kCamera.width, kCamera.height, 1, 1.0f};
  ImageF colour{kCamera.width, kCamera.height, 3, 0.25f};
};

TEST(ObservationGrid, WallVoxelsLieOnTheWallAndFaceTheCamera) {
  fusion::TsdfVolume geometry(geometry_params());
  fusion::VisibleBlocks blocks;
  Wall wall;
  fusion::integrate(geometry, wall.depth, wall.colour, kCamera, Pose::Identity(), blocks);
  ObservationGrid grid(grid_params());
  const auto& visible =
      grid.collect(wall.depth, wall.colour, kCamera, Pose::Identity(), 0.5f, geometry, 0);
  ASSERT_GT(visible.size(), 50u);
  for (const VisibleVoxel& seen : visible) {
    const int v = seen.voxel;
    ASSERT_TRUE(grid.has_surface(v));
    EXPECT_NEAR(grid.position(v).z(), 1.0f, 2e-3f);
    EXPECT_NEAR(grid.normal(v).z(), -1.0f, 1e-3f);
    ASSERT_EQ(grid.observation_count(v), 1);
    const Observation& o = grid.observations(v)[0];
    EXPECT_NEAR(o.colour.x(), 0.5f, 1e-6f) << "radiance = colour / exposure";
    EXPECT_NEAR(o.direction.norm(), 1.0f, 1e-5f);
    EXPECT_LT(o.direction.z(), 0.0f) << "towards the camera";
    // The voxel contains its surface point.
    EXPECT_EQ(grid.find(grid.position(v)), v);
  }
}

TEST(ObservationGrid, OccludedAndFarVoxelsAreNotObserved) {
  fusion::TsdfVolume geometry(geometry_params());
  fusion::VisibleBlocks blocks;
  Wall wall;
  fusion::integrate(geometry, wall.depth, wall.colour, kCamera, Pose::Identity(), blocks);
  ObservationGrid grid(grid_params());
  grid.collect(wall.depth, wall.colour, kCamera, Pose::Identity(), 1.0f, geometry, 0);
  // Now an occluder at 0.6 m covers the view: the wall's voxels fail the depth test.
  Wall occluder;
  occluder.depth = ImageF(kCamera.width, kCamera.height, 1, 0.6f);
  const auto& visible =
      grid.collect(occluder.depth, occluder.colour, kCamera, Pose::Identity(), 1.0f, geometry, 1);
  for (const VisibleVoxel& seen : visible) EXPECT_NEAR(grid.position(seen.voxel).z(), 0.6f, 0.05f);
  int wall_observations = 0;
  for (int v = 0; v < int(grid.voxel_count()); ++v)
    if (grid.has_surface(v) && std::abs(grid.position(v).z() - 1.0f) < 0.01f)
      wall_observations = std::max(wall_observations, grid.observation_count(v));
  EXPECT_EQ(wall_observations, 1) << "the occluded wall got no second observation";
}

TEST(ObservationGrid, ObservationsAccumulateUpToTheCapacity) {
  fusion::TsdfVolume geometry(geometry_params());
  fusion::VisibleBlocks blocks;
  Wall wall;
  ObservationGridParams params = grid_params();
  params.observations_per_voxel = 4;
  ObservationGrid grid(params);
  for (int frame = 0; frame < 7; ++frame) {
    // The camera slides sideways: new directions every frame.
    Pose pose = Pose::Identity();
    pose.translation() = Eigen::Vector3d(0.03 * frame, 0, 0);
    fusion::integrate(geometry, wall.depth, wall.colour, kCamera, pose, blocks);
    grid.collect(wall.depth, wall.colour, kCamera, pose, 1.0f, geometry, frame);
  }
  int full = 0;
  for (int v = 0; v < int(grid.voxel_count()); ++v) {
    EXPECT_LE(grid.observation_count(v), 4);
    full += grid.observation_count(v) == 4;
  }
  EXPECT_GT(full, 20);
}

TEST(ObservationGrid, VoxelsWithoutSurfaceAreRetriedEverLessOften) {
  // Frames 0-8 see the wall before any geometry is fused: its voxels find no surface at frame 0
  // and at their first retry (frame 8); the second retry waits twice as long (frame 24).
  fusion::TsdfVolume geometry(geometry_params());
  fusion::VisibleBlocks blocks;
  Wall wall;
  ObservationGrid grid(grid_params());
  ASSERT_EQ(grid.params().geometry_refresh_frames, 8);
  for (int frame = 0; frame <= 24; ++frame) {
    if (frame == 9)
      fusion::integrate(geometry, wall.depth, wall.colour, kCamera, Pose::Identity(), blocks);
    const auto& visible =
        grid.collect(wall.depth, wall.colour, kCamera, Pose::Identity(), 1.0f, geometry, frame);
    if (frame < 24)
      EXPECT_TRUE(visible.empty()) << "frame " << frame;
    else
      EXPECT_GT(visible.size(), 50u);
  }
}

TEST(ObservationGrid, BadInputsAndExhaustion) {
  EXPECT_NE(std::string(test::error_of([] {
                          ObservationGrid(ObservationGridParams{.surface_retry_doublings = 9});
                        }).what())
                .find("surface_retry_doublings"),
            std::string::npos);
  EXPECT_NE(std::string(test::error_of([] {
                          ObservationGrid(ObservationGridParams{.voxel_size_m = 0.03});
                        }).what())
                .find("voxel_size_m"),
            std::string::npos);
  fusion::TsdfVolume geometry(geometry_params());
  Wall wall;
  ObservationGrid grid(grid_params());
  const ImageF small(10, 10, 1, 1.0f);
  EXPECT_NE(std::string(test::error_of([&] {
                          grid.collect(small, wall.colour, kCamera, Pose::Identity(), 1.0f,
                                       geometry, 0);
                        }).what())
                .find("intrinsics' size"),
            std::string::npos);
  ObservationGrid tiny(ObservationGridParams{.voxel_capacity = 16});
  EXPECT_NE(std::string(test::error_of([&] {
                          tiny.collect(wall.depth, wall.colour, kCamera, Pose::Identity(), 1.0f,
                                       geometry, 0);
                        }).what())
                .find("exhausted"),
            std::string::npos);
}

}  // namespace
}  // namespace glint::reflectance
