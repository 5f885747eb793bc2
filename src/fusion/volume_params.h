#pragma once
// Parameters of the voxel-hashed TSDF volume (VoxelHashing, Niessner et al. 2013; paper 1 §3.3).
#include <cstddef>

namespace glint::fusion {

// Voxels per block side: blocks are 8x8x8 voxels (VoxelHashing's SDF_BLOCK_SIZE). A voxel's
// block coordinate is its coordinate >> kBlockShift (floor division, also below zero).
inline constexpr int kBlockShift = 3;
inline constexpr int kBlockSide = 1 << kBlockShift;
inline constexpr int kVoxelsPerBlock = kBlockSide * kBlockSide * kBlockSide;

struct VolumeParams {
  double voxel_size_m = 0.005;
  // Truncation band half-width at depth z: truncation_m + truncation_per_depth * z (metres),
  // VoxelHashing's getTruncation() with its defaults; the band grows with the sensor noise.
  double truncation_m = 0.02;
  double truncation_per_depth = 0.01;
  // The running weight saturates here (VoxelHashing's integrationWeightMax); a whole number in
  // [1, 255], as weights are kept in a byte.
  float max_weight = 255;
  // Fixed pool: at most this many blocks (2.5 KiB each, 8.5 KiB with colour); memory is
  // committed as blocks are used.
  // Running out throws glint::Error (fusion/voxel_block_hash.h).
  std::size_t block_capacity = std::size_t{1} << 18;
  // Every n-th pixel of every n-th row allocates blocks along its ray (Open3D's DepthTouch uses
  // 4): neighbouring rays' truncation bands overlap by far more than n pixels at block scale.
  int allocation_stride_px = 4;
  // Depth measurements outside [depth_min_m, depth_max_m] are ignored.
  double depth_min_m = 0.1;
  double depth_max_m = 4.0;
  // Keep a fused linear RGB per voxel (mesh and ray-cast colours). The reflectance pipeline
  // keeps its colours in the observation grid and turns this off: each new block then fills
  // 2.5 KiB instead of 8.5, and block allocation clears less.
  bool colour = true;
  // Far field: a block whose centre lies where one voxel spans less than `far_voxel_pixels`
  // pixels (depth > voxel_size_m * fx / far_voxel_pixels) is fused only every
  // `far_fusion_every`-th frame (after its first fusion), staggered over the blocks so that
  // each frame fuses an even share. There a pixel's ray passes several voxels, which all read the
  // same depth sample, and a frame moves the sample little against the last; the 5 mm voxels of a
  // room's far walls were two thirds of the blocks fused per frame. 1: every block every frame.
  int far_fusion_every = 1;
  double far_voxel_pixels = 0.5;

  double block_size_m() const { return voxel_size_m * kBlockSide; }
  // The depth beyond which blocks count as far field, for a camera of focal length fx (pixels).
  double far_field_depth_m(double fx) const { return voxel_size_m * fx / far_voxel_pixels; }
  double truncation_at(double depth_m) const {
    return truncation_m + truncation_per_depth * depth_m;
  }
};

// Throws glint::Error naming the bad parameter (non-positive sizes, depth range, capacity).
void validate(const VolumeParams& params);

}  // namespace glint::fusion
