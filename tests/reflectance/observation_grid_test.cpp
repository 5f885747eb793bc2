// Observation collection on analytic depth images: surface points and normals from the fused
// TSDF, the visibility test, radiance units, pool exhaustion.
#include "reflectance/observation_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
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
    EXPECT_NEAR(o.colour().x(), 0.5f, 1e-6f) << "radiance = colour / exposure";
    EXPECT_NEAR(o.direction().norm(), 1.0f, 5e-5f) << "unit, to 16-bit fractions";
    EXPECT_LT(o.direction().z(), 0.0f) << "towards the camera";
    // The voxel contains its surface point.
    EXPECT_EQ(grid.find(grid.position(v)), v);
  }
}

// The wall fused and observed once from the origin.
struct ObservedWall {
  fusion::TsdfVolume geometry{geometry_params()};
  ObservationGrid grid{grid_params()};
  ObservedWall() {
    const Wall wall;
    fusion::VisibleBlocks blocks;
    fusion::integrate(geometry, wall.depth, wall.colour, kCamera, Pose::Identity(), blocks);
    grid.collect(wall.depth, wall.colour, kCamera, Pose::Identity(), 1.0f, geometry, 0);
  }
};

TEST(ObservationGrid, FindVoxelsLooksUpACubeOfVoxelsAsFindVoxelDoes) {
  const ObservedWall observed;
  const ObservationGrid& grid = observed.grid;
  // Cubes straddling the wall (voxel z = 49 and 50 at 2 cm) at negative and positive x, y and
  // block boundaries on either side of `first`; one far from it has no voxel.
  int found = 0;
  for (const Eigen::Vector3i& first : {Eigen::Vector3i(-3, -2, 48), Eigen::Vector3i(0, 1, 47),
                                       Eigen::Vector3i(5, -6, 49), Eigen::Vector3i(-1, -1, 20)})
    for (const int n : {1, 3, 4}) {
      std::array<int, 64> voxels;
      grid.find_voxels(first, n, voxels.data());
      for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
          for (int x = 0; x < n; ++x) {
            const int expected = grid.find_voxel(first + Eigen::Vector3i(x, y, z));
            EXPECT_EQ(voxels[std::size_t((z * n + y) * n + x)], expected);
            found += expected >= 0;
          }
    }
  EXPECT_GT(found, 40);
  std::array<int, 125> too_many;
  EXPECT_THROW(grid.find_voxels({0, 0, 49}, 5, too_many.data()), Error);
  EXPECT_THROW(grid.find_voxels({0, 0, 49}, 0, too_many.data()), Error);
}

TEST(ObservationGrid, OccludedAndFarVoxelsAreNotObserved) {
  ObservedWall observed;
  ObservationGrid& grid = observed.grid;
  // Now an occluder at 0.6 m covers the view: the wall's voxels fail the depth test.
  Wall occluder;
  occluder.depth = ImageF(kCamera.width, kCamera.height, 1, 0.6f);
  const auto& visible = grid.collect(occluder.depth, occluder.colour, kCamera, Pose::Identity(),
                                     1.0f, observed.geometry, 1);
  for (const VisibleVoxel& seen : visible) EXPECT_NEAR(grid.position(seen.voxel).z(), 0.6f, 0.05f);
  int wall_observations = 0;
  for (int v = 0; v < int(grid.voxel_count()); ++v)
    if (grid.has_surface(v) && std::abs(grid.position(v).z() - 1.0f) < 0.01f)
      wall_observations = std::max(wall_observations, grid.observation_count(v));
  EXPECT_EQ(wall_observations, 1) << "the occluded wall got no second observation";
}

// Pool indices, and with them the order of a frame's voxels (which the segments' reservoirs and
// samples follow), are handed out in image-row order whatever the threads do; the surface points
// and refitted normals do not depend on how the blocks were split among threads either.
TEST(ObservationGrid, VoxelIndicesDoNotDependOnTheNumberOfThreads) {
  // A tilted wall seen from three poses: every frame allocates new blocks.
  const auto run = [](int threads) {
    const auto limit = limit_threads(threads);
    fusion::TsdfVolume geometry(geometry_params());
    ObservationGridParams params = grid_params();
    params.voxel_capacity = 1 << 17;
    ObservationGrid grid(params);
    ImageF depth(kCamera.width, kCamera.height, 1);
    for (int y = 0; y < kCamera.height; ++y)
      for (int x = 0; x < kCamera.width; ++x) depth.at(x, y, 0) = 0.8f + 0.006f * float(x);
    const ImageF colour(kCamera.width, kCamera.height, 3, 0.25f);
    struct Seen {
      VisibleVoxel voxel;
      Eigen::Vector3f position, normal;
    };
    std::vector<Seen> all;
    for (int frame = 0; frame < 3; ++frame) {
      Pose pose = Pose::Identity();
      pose.translation() = Eigen::Vector3d(0.15 * frame, 0.05 * frame, 0);
      fusion::VisibleBlocks blocks;
      fusion::integrate(geometry, depth, colour, kCamera, pose, blocks);
      for (const VisibleVoxel& seen :
           grid.collect(depth, colour, kCamera, pose, 1.0f, geometry, frame))
        all.push_back({seen, grid.position(seen.voxel), grid.normal(seen.voxel)});
    }
    return all;
  };
  const auto one = run(1), many = run(0);
  ASSERT_GT(one.size(), 100u);
  ASSERT_EQ(one.size(), many.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].voxel.voxel, many[i].voxel.voxel) << i;
    EXPECT_EQ(one[i].voxel.pixel, many[i].voxel.pixel) << i;
    EXPECT_EQ(one[i].position, many[i].position) << i;
    EXPECT_EQ(one[i].normal, many[i].normal) << i;
  }
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

// A wall fused once and grid parameters with a 1 degree observation spacing: the spacing
// tests move the camera along the wall.
class ObservationSpacing : public ::testing::Test {
 protected:
  ObservationSpacing() : geometry(geometry_params()) {
    fusion::integrate(geometry, wall.depth, wall.colour, kCamera, Pose::Identity(), blocks);
    params.min_observation_spacing_deg = 1;
  }
  static Pose pose_at(double x_m) {
    Pose pose = Pose::Identity();
    pose.translation() = Eigen::Vector3d(x_m, 0, 0);
    return pose;
  }

  fusion::TsdfVolume geometry;
  fusion::VisibleBlocks blocks;
  Wall wall;
  ObservationGridParams params = grid_params();
};

TEST_F(ObservationSpacing, ObservationsCloserThanTheSpacingToTheNewestAreNotStored) {
  // The camera creeps 1 mm per frame (0.06 degrees at 1 m), which stores nothing new although
  // every voxel stays seen, then jumps 3 cm (1.7 degrees).
  ObservationGrid grid(params);
  const std::size_t first_seen =
      grid.collect(wall.depth, wall.colour, kCamera, pose_at(0), 1.0f, geometry, 0).size();
  ASSERT_GT(first_seen, 50u);
  const auto max_count = [&] {
    int most = 0;
    for (const VisibleVoxel& seen : grid.visible())
      most = std::max(most, grid.observation_count(seen.voxel));
    return most;
  };
  for (int frame = 1; frame <= 5; ++frame) {
    const auto& visible = grid.collect(wall.depth, wall.colour, kCamera, pose_at(0.001 * frame),
                                       1.0f, geometry, frame);
    EXPECT_GE(visible.size(), first_seen - 10) << "frame " << frame << ": still seen";
    EXPECT_EQ(max_count(), 1) << "frame " << frame;
  }
  grid.collect(wall.depth, wall.colour, kCamera, pose_at(0.035), 1.0f, geometry, 6);
  EXPECT_EQ(max_count(), 2);
  params.min_observation_spacing_deg = 90;
  EXPECT_THROW(ObservationGrid{params}, Error);
}

TEST_F(ObservationSpacing, AnObservationIsStoredHoweverCloseOnceTheNewestIsOldEnough) {
  // spacing_max_frames 3: the creeping camera of the test above stores a voxel's first view,
  // then one every third frame, and its jump at once.
  params.spacing_max_frames = 3;
  ObservationGrid grid(params);
  const auto most_after = [&](double x_m, int frame) {
    int most = 0;
    for (const VisibleVoxel& seen :
         grid.collect(wall.depth, wall.colour, kCamera, pose_at(x_m), 1.0f, geometry, frame))
      most = std::max(most, grid.observation_count(seen.voxel));
    return most;
  };
  for (int frame = 0; frame <= 7; ++frame)
    EXPECT_EQ(most_after(0.001 * frame, frame), 1 + frame / 3) << "frame " << frame;
  EXPECT_EQ(most_after(0.035, 8), 4);
  params.spacing_max_frames = -1;
  EXPECT_THROW(ObservationGrid{params}, Error);
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

TEST(ObservationGrid, SettledSurfacesAreRefreshedEverLessOften) {
  // The wall's surface points are found at frame 0 and stay put at their refresh at frame 8, so
  // the next waits twice as long (frame 24). The wall moves 4 mm at frame 9: the points follow
  // at frame 24, not before. Having moved, they are refreshed 8 frames later again (frame 32),
  // and follow the wall's second 4 mm move at frame 25 there.
  Wall wall;
  fusion::VisibleBlocks blocks;
  const std::array<float, 3> wall_z{1.0f, 1.004f, 1.008f};
  const std::array<int, 3> wall_from_frame{0, 9, 25};
  std::vector<ImageF> depth;
  std::vector<std::unique_ptr<fusion::TsdfVolume>> geometry;
  for (const float z : wall_z) {
    depth.emplace_back(kCamera.width, kCamera.height, 1, z);
    geometry.push_back(std::make_unique<fusion::TsdfVolume>(geometry_params()));
    fusion::integrate(*geometry.back(), depth.back(), wall.colour, kCamera, Pose::Identity(),
                      blocks);
  }
  ObservationGrid grid(grid_params());
  ASSERT_EQ(grid.params().geometry_refresh_frames, 8);
  const std::array<int, 3> surface_from_frame{0, 24, 32};
  for (int frame = 0; frame <= 32; ++frame) {
    const int shown = int(std::upper_bound(wall_from_frame.begin(), wall_from_frame.end(), frame) -
                          wall_from_frame.begin()) -
                      1;
    const auto& visible = grid.collect(depth[shown], wall.colour, kCamera, Pose::Identity(), 1.0f,
                                       *geometry[shown], frame);
    ASSERT_GT(visible.size(), 50u) << "frame " << frame;
    std::vector<float> z;
    for (const VisibleVoxel& seen : visible) z.push_back(grid.position(seen.voxel).z());
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    const int followed =
        int(std::upper_bound(surface_from_frame.begin(), surface_from_frame.end(), frame) -
            surface_from_frame.begin()) -
        1;
    EXPECT_NEAR(z[z.size() / 2], wall_z[followed], 1e-3f) << "frame " << frame;
  }
}

// Pools for the metre-sized surfaces of the normal tests.
fusion::VolumeParams room_geometry_params() {
  fusion::VolumeParams params = geometry_params();
  params.block_capacity = 1 << 16;
  return params;
}

ObservationGridParams room_grid_params() {
  ObservationGridParams params = grid_params();
  params.voxel_capacity = 1 << 17;
  return params;
}

// A plane through (0, 0, depth_m) with unit normal n (facing the camera), as a depth image
// rounded to whole millimetres like a 16-bit depth PNG.
ImageF quantised_plane_depth(const Eigen::Vector3f& n, float depth_m, const Intrinsics& camera,
                             const Pose& camera_to_world) {
  ImageF depth(camera.width, camera.height, 1);
  const Eigen::Matrix3f rotation = camera_to_world.linear().cast<float>();
  const Eigen::Vector3f origin = camera_to_world.translation().cast<float>();
  const float offset = n.dot(Eigen::Vector3f(0, 0, depth_m));
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3f ray(float((x - camera.cx) / camera.fx),
                                float((y - camera.cy) / camera.fy), 1.0f);  // z = 1
      const float z = (offset - n.dot(origin)) / n.dot(rotation * ray);
      depth.at(x, y, 0) = z > 1.5f && z < 4.0f ? std::round(z * 1000.0f) / 1000.0f : 0.0f;
    }
  return depth;
}

// Median angle, in degrees, between the normals of the surfaced voxels and n.
double median_normal_error_deg(const ObservationGrid& grid, const Eigen::Vector3f& n) {
  std::vector<double> errors;
  for (int v = 0; v < int(grid.voxel_count()); ++v)
    if (grid.has_surface(v))
      errors.push_back(std::acos(std::clamp(double(grid.normal(v).dot(n)), -1.0, 1.0)) * 180 /
                       M_PI);
  EXPECT_GT(errors.size(), 100u);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

TEST(ObservationGrid, PlaneNormalsAreSteadierThanTheGradientOnQuantisedDepth) {
  // A tilted floor-like plane 2.5 m away, seen from a camera sliding sideways, its depth in
  // whole millimetres: the TSDF's gradient tilts with the quantisation steps, while the zero
  // crossings of neighbouring voxels stay on the plane.
  const Intrinsics camera{160, 120, 365.0, 365.0, 79.5, 59.5};  // ~7 mm pixels at 2.5 m
  const Eigen::Vector3f n = Eigen::Vector3f(0.35f, -0.6f, -1.0f).normalized();
  double error[2];
  for (const bool plane : {false, true}) {
    fusion::TsdfVolume geometry(room_geometry_params());
    fusion::VisibleBlocks blocks;
    ObservationGridParams params = room_grid_params();
    params.normal_from_neighbours = plane;
    ObservationGrid grid(params);
    const ImageF colour(camera.width, camera.height, 3, 0.5f);
    for (int frame = 0; frame < 10; ++frame) {
      Pose pose = Pose::Identity();
      pose.translation() = Eigen::Vector3d(0.01 * frame, 0.004 * frame, 0);
      const ImageF depth = quantised_plane_depth(n, 2.5f, camera, pose);
      fusion::integrate(geometry, depth, colour, camera, pose, blocks);
      grid.collect(depth, colour, camera, pose, 1.0f, geometry, frame);
    }
    error[plane] = median_normal_error_deg(grid, n);
  }
  EXPECT_LT(error[true], 0.5 * error[false]) << "gradient " << error[false] << " deg";
  EXPECT_LT(error[true], 0.5) << "degrees";
}

TEST(ObservationGrid, PlaneNormalsDoNotBlendTheFacesOfACrease) {
  // A room's floor (y = -0.51, normal +y) meeting its back wall (z = 2.01, normal -z), seen from
  // inside: a voxel near the crease has neighbours on both faces and must fit its own.
  fusion::TsdfVolume geometry(room_geometry_params());
  fusion::VisibleBlocks blocks;
  ObservationGrid grid(room_grid_params());
  const Intrinsics camera{160, 120, 200.0, 200.0, 79.5, 59.5};
  ImageF depth(camera.width, camera.height, 1);
  const ImageF colour(camera.width, camera.height, 3, 0.5f);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const float ray_y = float((y - camera.cy) / camera.fy);
      const float floor_z = ray_y > 0 ? 0.51f / ray_y : INFINITY;  // image y points down
      depth.at(x, y, 0) = std::min(2.01f, floor_z);
    }
  // The floor is y = +0.51 in camera coordinates (y down); its normal faces the camera: -y.
  const Eigen::Vector3f floor_normal(0, -1, 0), wall_normal(0, 0, -1);
  fusion::integrate(geometry, depth, colour, camera, Pose::Identity(), blocks);
  for (int frame = 0; frame < 2; ++frame)
    grid.collect(depth, colour, camera, Pose::Identity(), 1.0f, geometry, frame);
  int checked = 0;
  for (int v = 0; v < int(grid.voxel_count()); ++v) {
    if (!grid.has_surface(v)) continue;
    const Eigen::Vector3f p = grid.position(v);
    const float to_floor = std::fabs(p.y() - 0.51f), to_wall = std::fabs(p.z() - 2.01f);
    const float to_crease = std::hypot(to_floor, to_wall);
    if (to_crease < 0.015f || to_crease > 0.04f) continue;  // within a neighbour's reach
    const Eigen::Vector3f own = to_floor < to_wall ? floor_normal : wall_normal;
    EXPECT_GT(grid.normal(v).dot(own), std::cos(2.0f * float(M_PI) / 180))
        << "voxel at " << p.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 20);
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
