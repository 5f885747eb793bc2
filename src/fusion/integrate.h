#pragma once
// TSDF integration of one RGB-D frame into the voxel-hashed volume (thesis §2.1 "SDF update";
// VoxelHashing, Niessner et al. 2013 §4):
//  1. allocate_blocks(): every valid depth pixel (every allocation_stride_px-th in x and y)
//     allocates the blocks its ray crosses within the truncation band [d - t(d), d + t(d)];
//     the blocks touched form the frame's visible list.
//  2. integrate_blocks(): every voxel of every visible block is projected into the depth image
//     and fused (fusion/tsdf_kernels.h), in parallel over blocks; far-field blocks every
//     VolumeParams::far_fusion_every-th frame.
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "fusion/tsdf_volume.h"

namespace glint::fusion {

// The blocks seen by the latest frame (pool indices, each once).
struct VisibleBlocks {
  std::vector<int> indices;
  int frame = -1;  // id of the frame they belong to
};

// Step 1. depth_m: one channel, metres, 0 = no measurement, of the intrinsics' size. Throws
// glint::Error when the block pool is exhausted (the blocks allocated so far stay valid) or the
// size differs.
void allocate_blocks(TsdfVolume& volume, const ImageF& depth_m, const Intrinsics& intrinsics,
                     const Pose& camera_to_world, VisibleBlocks& visible);

// Step 2. colour: empty, or 3 channels of the depth's size (linear RGB); glint::Error otherwise.
void integrate_blocks(TsdfVolume& volume, const VisibleBlocks& visible, const ImageF& depth_m,
                      const ImageF& colour, const Intrinsics& intrinsics,
                      const Pose& camera_to_world);

// Both steps.
void integrate(TsdfVolume& volume, const ImageF& depth_m, const ImageF& colour,
               const Intrinsics& intrinsics, const Pose& camera_to_world, VisibleBlocks& visible);

}  // namespace glint::fusion
