// TSDF integration against analytic signed distances.
#include "fusion/integrate.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "fusion/tsdf_kernels.h"
#include "support/error_of.h"

namespace glint::fusion {
namespace {

const Intrinsics kCamera{64, 48, 50.0, 50.0, 31.5, 23.5};

VolumeParams plane_params() {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.truncation_m = 0.04;
  params.truncation_per_depth = 0.0;
  params.block_capacity = 4096;
  return params;
}

// Camera at the origin looking down +z at the wall z = wall_m: every pixel sees depth wall_m.
ImageF wall_depth(double wall_m) { return ImageF(kCamera.width, kCamera.height, 1, float(wall_m)); }

TEST(Integrate, FrontoParallelPlaneGivesTheAnalyticSdf) {
  TsdfVolume volume(plane_params());
  VisibleBlocks visible;
  integrate(volume, wall_depth(1.0), ImageF(), kCamera, Pose::Identity(), visible);
  ASSERT_GT(visible.indices.size(), 0u);
  EXPECT_EQ(visible.indices.size(), volume.block_count());

  int checked = 0;
  for (int block : visible.indices) {
    const Eigen::Vector3i first = volume.hash().block(block) * kBlockSide;
    for (int v = 0; v < kVoxelsPerBlock; ++v) {
      const Eigen::Vector3d p =
          (first + Eigen::Vector3i(v % 8, (v / 8) % 8, v / 64)).cast<double>() * 0.01;
      const Eigen::Vector2d pixel = kCamera.project(p);
      const bool in_view = p.z() > 0 && pixel.x() > 0 && pixel.y() > 0 &&
                           pixel.x() < kCamera.width - 1 && pixel.y() < kCamera.height - 1;
      const double sdf = 1.0 - p.z();
      if (!in_view) continue;
      if (sdf < -0.04 - 1e-6) {
        EXPECT_EQ(volume.weight(block)[v], 0.0f) << "behind the band: never observed";
        EXPECT_EQ(volume.sdf_m(block)[v], kUnobservedSdf);
        continue;
      }
      if (sdf < -0.04 + 1e-6) continue;
      EXPECT_EQ(volume.weight(block)[v], 1.0f);
      EXPECT_NEAR(volume.sdf_m(block)[v], std::min(sdf, 0.04), 1e-5) << p.transpose();
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

TEST(Integrate, RepeatedFramesAverageAndColourFollows) {
  TsdfVolume volume(plane_params());
  VisibleBlocks visible;
  ImageF colour(kCamera.width, kCamera.height, 3, 0.25f);
  integrate(volume, wall_depth(1.0), colour, kCamera, Pose::Identity(), visible);
  colour.values().assign(colour.values().size(), 0.75f);
  integrate(volume, wall_depth(1.02), colour, kCamera, Pose::Identity(), visible);
  const int block = volume.hash().find({0, 0, 12});  // voxels z = 0.96 .. 1.03 m
  ASSERT_GE(block, 0);
  const int voxel = 3 * 64;  // (0, 0, z = 0.99 m)
  EXPECT_EQ(volume.weight(block)[voxel], 2.0f);
  EXPECT_NEAR(volume.sdf_m(block)[voxel], 0.5 * (0.01 + 0.03), 1e-5);
  EXPECT_NEAR(volume.red(block)[voxel], 0.5, 1e-6);
}

// Weights are kept in a byte: the default clamp, 255, is reached and held, not wrapped to 0.
TEST(Integrate, WeightsSaturateAtTheByteLimit) {
  TsdfVolume volume(plane_params());
  ASSERT_EQ(volume.params().max_weight, 255.0f);
  VisibleBlocks visible;
  for (int frame = 0; frame < 257; ++frame)
    integrate(volume, wall_depth(frame < 255 ? 1.0 : 1.01), ImageF(), kCamera, Pose::Identity(),
              visible);
  const int block = volume.hash().find({0, 0, 12});
  ASSERT_GE(block, 0);
  const int voxel = 3 * 64;  // (0, 0, z = 0.99 m)
  EXPECT_EQ(volume.weight(block)[voxel], 255);
  // 255 observations of 0.01 m, then two of 0.02 m, each averaged in at weight 255.
  const double after_one = (0.01 * 255 + 0.02) / 256, after_two = (after_one * 255 + 0.02) / 256;
  EXPECT_NEAR(volume.sdf_m(block)[voxel], after_two, 1e-6);
}

// The vectorised block kernel (AVX-512, AVX2 or baseline, whichever this CPU runs) fuses every
// voxel as the scalar rule does, under a tilted camera, a depth that varies from pixel to pixel
// with holes and out-of-range values, the band growing with depth and the weight clamp reached.
TEST(Integrate, TheBlockKernelFollowsTheScalarRuleUnderATiltedCamera) {
  VolumeParams params = plane_params();
  params.truncation_per_depth = 0.02;
  params.depth_max_m = 1.4;
  params.max_weight = 3;
  TsdfVolume volume(params);
  Pose camera_to_world = Pose::Identity();
  camera_to_world.linear() =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, 1.0, 0.2).normalized()).toRotationMatrix();
  camera_to_world.translation() = Eigen::Vector3d(0.1, -0.05, 0.2);
  const auto surface = [](double offset_m) {
    ImageF depth(kCamera.width, kCamera.height, 1);
    for (int y = 0; y < kCamera.height; ++y)
      for (int x = 0; x < kCamera.width; ++x)
        depth.at(x, y, 0) = x % 7 == 3 ? 0.0f  // hole
                            : y % 11 == 5
                                ? 1.6f  // beyond depth_max
                                : float(1.0 + 0.2 * std::sin(0.3 * x) + 0.003 * y + offset_m);
    return depth;
  };
  VisibleBlocks visible;
  for (int frame = 0; frame < 4; ++frame)  // weights reach the clamp
    integrate(volume, surface(0.0), ImageF(), kCamera, camera_to_world, visible);
  std::vector<std::vector<float>> sdf_before, weight_before;
  for (const int block : visible.indices) {
    sdf_before.emplace_back(volume.sdf_m(block), volume.sdf_m(block) + kVoxelsPerBlock);
    weight_before.emplace_back(volume.weight(block), volume.weight(block) + kVoxelsPerBlock);
  }
  const ImageF depth = surface(0.013);
  integrate_blocks(volume, visible, depth, ImageF(), kCamera, camera_to_world);

  const FrameConstants k{50.0f,          50.0f,          31.5f, 23.5f, kCamera.width,
                         kCamera.height, 0.1f,           1.4f,  0.04f, 0.02f,
                         3.0f,           depth.plane(0), {},    {},    {}};
  const Pose world_to_camera = camera_to_world.inverse();
  int checked = 0, fused = 0, borderline = 0;
  for (std::size_t b = 0; b < visible.indices.size(); ++b) {
    const int block = visible.indices[b];
    const Eigen::Vector3i first = volume.hash().block(block) * kBlockSide;
    for (int v = 0; v < kVoxelsPerBlock; ++v) {
      const Eigen::Vector3d c =
          world_to_camera *
          ((first + Eigen::Vector3i(v % 8, (v / 8) % 8, v / 64)).cast<double>() * 0.01);
      // Rounding may put a voxel on either side of a pixel border or of the band's far edge.
      const double u = 50.0 * c.x() / c.z() + 32.0, w = 50.0 * c.y() / c.z() + 24.0;
      const auto near_border = [](double t) { return std::abs(t - std::round(t)) < 1e-3; };
      if (c.z() > 0 && (near_border(u) || near_border(w))) {
        ++borderline;
        continue;
      }
      float sdf = sdf_before[b][std::size_t(v)], weight = weight_before[b][std::size_t(v)];
      fused += fuse_voxel_projective(k, float(c.x()), float(c.y()), float(c.z()), sdf, weight) >= 0;
      const float d =
          c.z() > 0 ? depth.at(int(std::clamp(u, 0.0, 63.0)), int(std::clamp(w, 0.0, 47.0)), 0)
                    : 0.0f;
      if (std::abs(d - c.z() + (0.04 + 0.02 * d)) < 1e-4) {
        ++borderline;
        continue;
      }
      ASSERT_EQ(volume.weight(block)[v], weight) << "block " << block << " voxel " << v;
      ASSERT_NEAR(volume.sdf_m(block)[v], sdf, 1e-5) << "block " << block << " voxel " << v;
      ++checked;
    }
  }
  EXPECT_GT(fused, 2000);
  EXPECT_LT(borderline, checked / 100);
}

TEST(Integrate, AVolumeWithoutColourFusesTheSameDistancesAndRefusesColour) {
  VolumeParams params = plane_params();
  TsdfVolume with_colour(params);
  params.colour = false;
  TsdfVolume without_colour(params);
  ASSERT_FALSE(without_colour.has_colour());
  VisibleBlocks visible;
  const ImageF colour(kCamera.width, kCamera.height, 3, 0.25f);
  integrate(with_colour, wall_depth(1.0), colour, kCamera, Pose::Identity(), visible);
  integrate(without_colour, wall_depth(1.0), ImageF(), kCamera, Pose::Identity(), visible);
  ASSERT_EQ(without_colour.block_count(), with_colour.block_count());
  for (int b = 0; b < int(with_colour.block_count()); ++b) {
    const int same = without_colour.hash().find(with_colour.hash().block(b));
    ASSERT_GE(same, 0);
    for (int v = 0; v < kVoxelsPerBlock; ++v) {
      ASSERT_EQ(without_colour.weight(same)[v], with_colour.weight(b)[v]);
      ASSERT_EQ(without_colour.sdf_m(same)[v], with_colour.sdf_m(b)[v]);
    }
  }
  const Error error = test::error_of([&] {
    integrate(without_colour, wall_depth(1.0), colour, kCamera, Pose::Identity(), visible);
  });
  EXPECT_NE(error.reason().find("keeps no colour"), std::string::npos) << error.what();
}

TEST(Integrate, ExhaustedPoolIsAClearError) {
  VolumeParams params = plane_params();
  params.block_capacity = 5;
  TsdfVolume volume(params);
  VisibleBlocks visible;
  const Error error = test::error_of(
      [&] { integrate(volume, wall_depth(1.0), ImageF(), kCamera, Pose::Identity(), visible); });
  EXPECT_NE(error.reason().find("all 5 blocks are in use"), std::string::npos) << error.what();
  EXPECT_EQ(volume.block_count(), 5u);
}

TEST(Integrate, MismatchedImagesAndBadParametersAreErrors) {
  TsdfVolume volume(plane_params());
  VisibleBlocks visible;
  EXPECT_THROW(
      integrate(volume, ImageF(10, 10, 1, 1.0f), ImageF(), kCamera, Pose::Identity(), visible),
      Error);
  EXPECT_THROW(
      integrate(volume, wall_depth(1.0), ImageF(8, 8, 3), kCamera, Pose::Identity(), visible),
      Error);
  VolumeParams bad = plane_params();
  bad.voxel_size_m = 0;
  EXPECT_THROW(TsdfVolume{bad}, Error);
  bad = plane_params();
  bad.far_fusion_every = 0;
  const Error error = test::error_of([&] { TsdfVolume{bad}; });
  EXPECT_NE(std::string(error.what()).find("far_fusion_every"), std::string::npos);
  // Weights are whole counts in a byte.
  for (const float max_weight : {0.0f, 2.5f, 256.0f}) {
    bad = plane_params();
    bad.max_weight = max_weight;
    const Error weight_error = test::error_of([&] { TsdfVolume{bad}; });
    EXPECT_NE(std::string(weight_error.what()).find("max_weight"), std::string::npos) << max_weight;
  }
}

TEST(Integrate, FarFieldBlocksAreFusedEveryNthFrameStaggered) {
  // fx = 50 px and 1 cm voxels: a voxel spans half a pixel at 1 m, where the far field starts.
  // The left half of the image sees a wall at 0.6 m, the right half one at 1.6 m.
  VolumeParams params = plane_params();
  params.far_fusion_every = 2;
  ASSERT_NEAR(params.far_field_depth_m(kCamera.fx), 1.0, 1e-12);
  TsdfVolume volume(params);
  VisibleBlocks visible;
  ImageF depth = wall_depth(0.6);
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = kCamera.width / 2; x < kCamera.width; ++x) depth.at(x, y, 0) = 1.6f;
  const auto fused_times = [&](int block) {  // the largest weight in the block
    const std::uint8_t* weight = volume.weight(block);
    return int(*std::max_element(weight, weight + kVoxelsPerBlock));
  };
  const auto is_far = [&](int block) {
    return volume.block_origin_m(volume.hash().block(block)).z() + 0.04 > 1.0;
  };
  // The first frame fuses every block, the second every near block and half the far ones.
  for (int frame = 0; frame < 2; ++frame)
    integrate(volume, depth, ImageF(), kCamera, Pose::Identity(), visible);
  int far_twice = 0, far_once = 0, near = 0;
  for (const int block : visible.indices) {
    if (fused_times(block) == 0) continue;  // only the band's outer voxels: never reached
    if (!is_far(block)) {
      EXPECT_EQ(fused_times(block), 2);
      ++near;
      continue;
    }
    ASSERT_GE(fused_times(block), 1);
    (fused_times(block) == 2 ? far_twice : far_once) += 1;
  }
  ASSERT_GT(near, 0);
  EXPECT_GT(far_twice, 0) << "half the far blocks in each frame";
  EXPECT_GT(far_once, 0);
  // The third frame fuses the other half.
  integrate(volume, depth, ImageF(), kCamera, Pose::Identity(), visible);
  for (const int block : visible.indices) {
    if (fused_times(block) == 0) continue;
    EXPECT_EQ(fused_times(block), is_far(block) ? 2 : 3) << "block " << block;
    EXPECT_EQ(volume.fusions(block), is_far(block) ? 2 : 3);
  }
}

TEST(Integrate, ZeroDepthIsNoMeasurement) {
  TsdfVolume volume(plane_params());
  VisibleBlocks visible;
  integrate(volume, wall_depth(0.0), ImageF(), kCamera, Pose::Identity(), visible);
  EXPECT_EQ(volume.block_count(), 0u);
  EXPECT_TRUE(visible.indices.empty());
}

}  // namespace
}  // namespace glint::fusion
