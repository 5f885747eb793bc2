#pragma once
// TsdfSampler: reads the TSDF at arbitrary world points (nearest voxel or trilinear), caching
// the last block looked up (rays and neighbouring samples mostly stay in one block). One sampler
// per thread; the volume must not change while it is read.
#include <Eigen/Core>
#include <cmath>

#include "fusion/tsdf_volume.h"

namespace glint::fusion {

class TsdfSampler {
 public:
  explicit TsdfSampler(const TsdfVolume& volume)
      : volume_(volume), inverse_voxel_(1.0f / float(volume.params().voxel_size_m)) {}

  enum class Sample { unallocated, unobserved, observed };

  // Nearest voxel to world point p.
  Sample nearest(const Eigen::Vector3f& p, float& sdf_m) {
    const Eigen::Vector3f v = p * inverse_voxel_;
    return voxel(round_to_int(v.x()), round_to_int(v.y()), round_to_int(v.z()), sdf_m);
  }

  // Trilinear interpolation of the 8 voxels around p; false when any of them is unobserved.
  bool trilinear(const Eigen::Vector3f& p, float& sdf_m) {
    const Eigen::Vector3f v = p * inverse_voxel_;
    const int x = int(std::floor(v.x())), y = int(std::floor(v.y())), z = int(std::floor(v.z()));
    const float fx = v.x() - x, fy = v.y() - y, fz = v.z() - z;
    float corner[8];
    for (int c = 0; c < 8; ++c) {
      if (voxel(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1), corner[c]) != Sample::observed)
        return false;
    }
    const auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    sdf_m = lerp(lerp(lerp(corner[0], corner[1], fx), lerp(corner[2], corner[3], fx), fy),
                 lerp(lerp(corner[4], corner[5], fx), lerp(corner[6], corner[7], fx), fy), fz);
    return true;
  }

  // Colour of the nearest voxel (call after an observed sample there).
  Eigen::Vector3f nearest_colour(const Eigen::Vector3f& p) {
    const Eigen::Vector3f v = p * inverse_voxel_;
    float unused;
    const int x = round_to_int(v.x()), y = round_to_int(v.y()), z = round_to_int(v.z());
    if (voxel(x, y, z, unused) != Sample::observed) return Eigen::Vector3f::Zero();
    const int index = voxel_in_block(x, y, z);
    return {volume_.red(block_)[index], volume_.green(block_)[index], volume_.blue(block_)[index]};
  }

  // Global voxel coordinates -> its sample.
  Sample voxel(int x, int y, int z, float& sdf_m) {
    const Eigen::Vector3i block(x >> 3, y >> 3, z >> 3);  // floor division by 8
    if (block != cached_coordinates_ || !cached_) {
      cached_coordinates_ = block;
      cached_ = true;
      block_ = volume_.hash().find(block);
    }
    if (block_ < 0) return Sample::unallocated;
    const int index = voxel_in_block(x, y, z);
    if (volume_.weight(block_)[index] <= 0) return Sample::unobserved;
    sdf_m = volume_.sdf_m(block_)[index];
    return Sample::observed;
  }

 private:
  static int round_to_int(float value) { return static_cast<int>(std::floor(value + 0.5f)); }

  const TsdfVolume& volume_;
  float inverse_voxel_;
  Eigen::Vector3i cached_coordinates_ = Eigen::Vector3i::Zero();
  bool cached_ = false;
  int block_ = -1;
};

}  // namespace glint::fusion
