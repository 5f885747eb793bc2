// Re-rendering: Ward shading under point lights against the formula, and the refined albedo's
// interpolation between observation voxels of one segment.
#include "reflectance/material_maps.h"

#include <gtest/gtest.h>

#include "fusion/integrate.h"

namespace glint::reflectance {
namespace {

TEST(MaterialMaps, ShadingIsEquationSixSummedOverTheLights) {
  render::WardMaterial m;
  m.kd = {0.5f, 0.4f, 0.3f};
  m.ks = {0.1f, 0.1f, 0.1f};
  m.alpha = 0.2f;
  const Eigen::Vector3f p(0, 0, 0), n(0, 0, 1), eye(1, 0, 2);
  std::vector<render::PointLight> lights(2);
  lights[0].position = {0, 0, 2};
  lights[0].intensity = {4, 4, 4};
  lights[1].position = {0, 0, -1};  // below the surface: no contribution
  lights[1].intensity = {9, 9, 9};
  const Eigen::Vector3f wi(0, 0, 1), wo = (eye - p).normalized();
  const Eigen::Vector3f expected = render::ward_brdf(m, n, wi, wo) * 4.0f / 4.0f;  // I/r^2 cos
  EXPECT_TRUE(shade_ward(m, p, n, eye, lights).isApprox(expected, 1e-6f));
}

TEST(MaterialMaps, RefinedAlbedoInterpolatesWithinTheSegmentOnly) {
  // 4-pixel TSDF allocation stride = 3.3 cm < one 4 cm block at 1 m: no block rows missing.
  const Intrinsics camera{80, 60, 120.0, 120.0, 39.5, 29.5};
  fusion::VolumeParams volume;
  volume.block_capacity = 1 << 12;
  fusion::TsdfVolume geometry(volume);
  fusion::VisibleBlocks blocks;
  // A wall at z = 1.005 m, inside one layer of 2 cm voxels (not on a voxel face).
  const ImageF depth(80, 60, 1, 1.005f), colour(80, 60, 3, 0.2f);
  fusion::integrate(geometry, depth, colour, camera, Pose::Identity(), blocks);
  ObservationGrid grid(ObservationGridParams{.voxel_capacity = 1 << 14});
  const auto& visible = grid.collect(depth, colour, camera, Pose::Identity(), 1.0f, geometry, 0);
  ASSERT_GT(visible.size(), 20u);
  for (const VisibleVoxel& seen : visible) {
    grid.segment(seen.voxel) = 3;
    grid.has_refined_kd(seen.voxel) = true;
    // A ramp in x: linear, so trilinear interpolation reproduces it between voxel centres.
    grid.refined_kd(seen.voxel) = Eigen::Vector3f::Constant(0.5f + grid.position(seen.voxel).x());
  }
  // Centre of the wall, between voxel centres.
  const Eigen::Vector3f p(0.013f, -0.007f, 1.005f);
  Eigen::Vector3f kd;
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  EXPECT_NEAR(kd.x(), 0.5f + p.x(), 5e-3f);
  EXPECT_FALSE(interpolate_refined_kd(grid, p, 4, kd)) << "another segment's voxels are not used";
}

}  // namespace
}  // namespace glint::reflectance
