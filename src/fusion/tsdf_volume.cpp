#include "fusion/tsdf_volume.h"

#include <algorithm>

namespace glint::fusion {

namespace {
template <class T = float>
PoolArray<T> voxel_pool(const VolumeParams& params) {
  return make_pool<T>(params.block_capacity * kVoxelsPerBlock, "TSDF volume");
}
}  // namespace

TsdfVolume::TsdfVolume(const VolumeParams& params)
    : params_((validate(params), params)),
      hash_(params.block_capacity),
      sdf_m_(voxel_pool(params)),
      red_(params.colour ? voxel_pool(params) : PoolArray<float>()),
      green_(params.colour ? voxel_pool(params) : PoolArray<float>()),
      blue_(params.colour ? voxel_pool(params) : PoolArray<float>()),
      weight_(voxel_pool<std::uint8_t>(params)),
      fusions_(make_pool<std::uint8_t>(params.block_capacity, "TSDF volume")),
      last_visible_(new std::atomic<int>[params.block_capacity]) {
  for (std::size_t b = 0; b < params.block_capacity; ++b) last_visible_[b].store(-1);
}

int TsdfVolume::allocate(const Eigen::Vector3i& block) {
  const VoxelBlockHash::Insertion insertion = hash_.insert(block);
  if (insertion.inserted) {
    const int b = insertion.index;
    std::fill_n(sdf_m(b), kVoxelsPerBlock, kUnobservedSdf);
    std::fill_n(weight(b), kVoxelsPerBlock, std::uint8_t{0});
    if (has_colour()) {
      std::fill_n(red(b), kVoxelsPerBlock, 0.0f);
      std::fill_n(green(b), kVoxelsPerBlock, 0.0f);
      std::fill_n(blue(b), kVoxelsPerBlock, 0.0f);
    }
  }
  return insertion.index;
}

}  // namespace glint::fusion
