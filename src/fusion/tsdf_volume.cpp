#include "fusion/tsdf_volume.h"

#include <algorithm>
#include <cmath>

namespace glint::fusion {

namespace {
template <class T>
PoolArray<T> voxel_pool(const VolumeParams& params) {
  return make_pool<T>(params.block_capacity * kVoxelsPerBlock, "TSDF volume");
}
}  // namespace

TsdfVolume::TsdfVolume(const VolumeParams& params)
    : params_((validate(params), params)),
      hash_(params.block_capacity),
      sdf_quantum_m_(float(params.truncation_at(params.depth_max_m) / kMaxSdfCode)),
      sdf_codes_(voxel_pool<std::int16_t>(params)),
      weights_(voxel_pool<std::uint8_t>(params)),
      red_(params.colour ? voxel_pool<float>(params) : PoolArray<float>()),
      green_(params.colour ? voxel_pool<float>(params) : PoolArray<float>()),
      blue_(params.colour ? voxel_pool<float>(params) : PoolArray<float>()),
      fusions_(make_pool<std::uint8_t>(params.block_capacity, "TSDF volume")),
      last_visible_(new std::atomic<int>[params.block_capacity]) {
  for (std::size_t b = 0; b < params.block_capacity; ++b) last_visible_[b].store(-1);
}

int TsdfVolume::allocate(const Eigen::Vector3i& block) {
  const VoxelBlockHash::Insertion insertion = hash_.insert(block);
  if (insertion.inserted) {
    const int b = insertion.index;
    std::fill_n(sdf_codes(b), kVoxelsPerBlock, std::int16_t{0});
    std::fill_n(weights(b), kVoxelsPerBlock, std::uint8_t{0});
    if (has_colour()) {
      std::fill_n(red(b), kVoxelsPerBlock, 0.0f);
      std::fill_n(green(b), kVoxelsPerBlock, 0.0f);
      std::fill_n(blue(b), kVoxelsPerBlock, 0.0f);
    }
  }
  return insertion.index;
}

void TsdfVolume::set_voxel(int block, int voxel, float sdf_m, int weight) {
  const float code =
      std::clamp(std::round(sdf_m / sdf_quantum_m_), float(-kMaxSdfCode), float(kMaxSdfCode));
  sdf_codes(block)[voxel] = std::int16_t(code);
  weights(block)[voxel] = std::uint8_t(std::clamp(weight, 0, 255));
}

}  // namespace glint::fusion
