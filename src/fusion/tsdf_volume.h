#pragma once
// TsdfVolume: the voxel-hashed truncated signed distance field with colour. Voxel data are flat
// structure-of-arrays pools indexed by block * kVoxelsPerBlock + voxel, voxel = (z*8 + y)*8 + x;
// the pools are allocated once (capacity from VolumeParams) and their pages are committed only
// as blocks are used.
//
// Voxel values: sdf_m, signed distance along the viewing ray in metres (positive in front of the
// surface), clamped to the truncation band, or kUnobservedSdf in a voxel never observed; weight,
// number of fused observations (saturating at VolumeParams::max_weight, at most 255; 0 exactly
// where sdf_m is kUnobservedSdf), one byte: integration streams a block's distances and weights
// through memory every frame, and float weights were half of those bytes;
// red, green, blue, weighted mean linear colour (only in volumes that keep colour).
#include <Eigen/Core>
#include <atomic>
#include <bit>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "core/pool_memory.h"
#include "fusion/host_device.h"
#include "fusion/volume_params.h"
#include "fusion/voxel_block_hash.h"

namespace glint::fusion {

// Index within its block of the voxel at global voxel coordinates (x, y, z) (any sign).
GLINT_HOST_DEVICE inline int voxel_in_block(int x, int y, int z) {
  return ((z & (kBlockSide - 1)) * kBlockSide + (y & (kBlockSide - 1))) * kBlockSide +
         (x & (kBlockSide - 1));
}

// The distance a new block's voxels hold until their first observation. Readers test it instead
// of the weight, so a sample reads one pool instead of two (the observation grid's surface
// refreshes stalled on the weights' cache misses as much as on the distances'). It is finite, so
// the first fusion's running average, (sdf * 0 + observation) / 1, takes the observation alone:
// no kernel treats it specially.
inline constexpr float kUnobservedSdf = std::numeric_limits<float>::max();
GLINT_HOST_DEVICE inline bool observed(float sdf_m) { return sdf_m != kUnobservedSdf; }

class TsdfVolume {
 public:
  explicit TsdfVolume(const VolumeParams& params = {});

  const VolumeParams& params() const { return params_; }
  VoxelBlockHash& hash() { return hash_; }
  const VoxelBlockHash& hash() const { return hash_; }
  std::size_t block_count() const { return hash_.size(); }

  // World position of a block's first voxel (its minimum corner voxel), metres.
  Eigen::Vector3d block_origin_m(const Eigen::Vector3i& block) const {
    return block.cast<double>() * params_.block_size_m();
  }

  // Inserts the block (unobserved: kUnobservedSdf, weight and colour 0) if absent; thread-safe
  // against concurrent calls. Returns its pool index or VoxelBlockHash::kPoolFull.
  int allocate(const Eigen::Vector3i& block);

  // Whether the volume keeps colour (VolumeParams::colour); red(), green(), blue() need it.
  bool has_colour() const { return params_.colour; }

  float* sdf_m(int block) { return sdf_m_.get() + voxel_offset(block); }
  std::uint8_t* weight(int block) { return weight_.get() + voxel_offset(block); }
  float* red(int block) { return red_.get() + voxel_offset(block); }
  float* green(int block) { return green_.get() + voxel_offset(block); }
  float* blue(int block) { return blue_.get() + voxel_offset(block); }
  const float* sdf_m(int block) const { return sdf_m_.get() + voxel_offset(block); }
  const std::uint8_t* weight(int block) const { return weight_.get() + voxel_offset(block); }
  const float* red(int block) const { return red_.get() + voxel_offset(block); }
  const float* green(int block) const { return green_.get() + voxel_offset(block); }
  const float* blue(int block) const { return blue_.get() + voxel_offset(block); }

  // A block's distances (2 KB) as 32 cache lines: line k holds the rows (z * 8 + y) = 2k and
  // 2k + 1. The lines holding the rows y0..y1 of the slices z0..z1 (block coordinates, 0..7),
  // as bits.
  static std::uint32_t distance_lines(int y0, int y1, int z0, int z1) {
    std::uint32_t lines = 0;
    for (int z = z0; z <= z1; ++z)
      for (int y = y0 & ~1; y <= y1; y += 2) lines |= 1u << ((z * kBlockSide + y) >> 1);
    return lines;
  }
  // Asks for the lines of a block's distances named by the bits of `lines` ahead of reading them
  // (TsdfSampler reads no weights).
  void prefetch_distance_lines(int block, std::uint32_t lines) const {
    static_assert(kVoxelsPerBlock * sizeof(float) == 32 * 64);
    constexpr int kFloatsPerLine = 64 / sizeof(float);
    for (; lines != 0; lines &= lines - 1)
      __builtin_prefetch(sdf_m(block) + std::countr_zero(lines) * kFloatsPerLine);
  }

  // How many frames have been fused into a block (saturating at 255). integrate_blocks counts
  // them; each block is fused by one thread at a time.
  int fusions(int block) const { return fusions_[block]; }
  void count_fusion(int block) {
    if (fusions_[block] < 255) ++fusions_[block];
  }

  // Marks a block seen in frame `frame`; true for the first caller per frame (thread-safe), so
  // the caller appends it to the frame's visible list exactly once.
  bool mark_visible(int block, int frame) {
    return last_visible_[block].exchange(frame, std::memory_order_relaxed) != frame;
  }

 private:
  static std::size_t voxel_offset(int block) {
    return static_cast<std::size_t>(block) * kVoxelsPerBlock;
  }

  VolumeParams params_;
  VoxelBlockHash hash_;
  PoolArray<float> sdf_m_, red_, green_, blue_;
  PoolArray<std::uint8_t> weight_, fusions_;
  std::unique_ptr<std::atomic<int>[]> last_visible_;
};

}  // namespace glint::fusion
