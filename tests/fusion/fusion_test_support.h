#pragma once
// Helpers shared by the fusion tests: volumes filled with analytic signed distance fields.
#include <functional>

#include "fusion/tsdf_volume.h"

namespace glint::fusion::test {

// Allocates every block whose centre lies within `band_m` (plus a block diagonal) of the zero
// set of `sdf` inside the cube [-extent_m, extent_m]^3 and sets each voxel to sdf (clamped to
// +-band_m), weight 1, colour (0.5, 0.5, 0.5).
inline void fill_analytic(TsdfVolume& volume,
                          const std::function<double(const Eigen::Vector3d&)>& sdf, double extent_m,
                          double band_m) {
  const double block = volume.params().block_size_m();
  const double voxel = volume.params().voxel_size_m;
  const int blocks = static_cast<int>(std::ceil(extent_m / block));
  for (int z = -blocks; z < blocks; ++z)
    for (int y = -blocks; y < blocks; ++y)
      for (int x = -blocks; x < blocks; ++x) {
        const Eigen::Vector3d centre =
            (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)) * block;
        if (std::abs(sdf(centre)) > band_m + block) continue;
        const int b = volume.allocate({x, y, z});
        for (int v = 0; v < kVoxelsPerBlock; ++v) {
          const Eigen::Vector3d p =
              (Eigen::Vector3i(x, y, z) * kBlockSide + Eigen::Vector3i(v % 8, (v / 8) % 8, v / 64))
                  .cast<double>() *
              voxel;
          volume.sdf_m(b)[v] = static_cast<float>(std::clamp(sdf(p), -band_m, band_m));
          volume.weight(b)[v] = 1;
          volume.red(b)[v] = volume.green(b)[v] = volume.blue(b)[v] = 0.5f;
        }
      }
}

}  // namespace glint::fusion::test
