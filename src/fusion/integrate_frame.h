#pragma once
// What the CPU (integrate.cpp) and CUDA (cuda_integrator.cpp) integration share for one frame:
// its constants in camera coordinates, where each block lies, and which visible blocks are fused.
#include <Eigen/Core>

#include "core/camera.h"
#include "core/image.h"
#include "fusion/integrate.h"
#include "fusion/tsdf_kernels.h"

namespace glint::fusion {

class FrameIntegration {
 public:
  // Throws glint::Error when the images do not match the intrinsics (depth: 1 channel; colour:
  // empty or 3 channels) or colour comes for a volume that keeps none.
  FrameIntegration(const TsdfVolume& volume, const VisibleBlocks& visible, const ImageF& depth_m,
                   const ImageF& colour, const Intrinsics& intrinsics, const Pose& camera_to_world);

  const FrameConstants& constants() const { return constants_; }

  // Camera coordinates of the block's voxel (0, 0, 0).
  Eigen::Vector3f block_origin(int block) const {
    return rotation_ * volume_.block_origin_m(volume_.hash().block(block)).cast<float>() +
           translation_;
  }

  // Whether the block is fused this frame: a far-field block only every far_fusion_every-th
  // frame, staggered over the blocks, but never before its first fusion (until then it holds no
  // surface for the reflectance pipeline's observation voxels to find).
  bool fused_now(int block, const Eigen::Vector3f& origin) const {
    return far_every_ <= 1 || (origin + half_block_).z() <= far_depth_ ||
           volume_.fusions(block) == 0 || (block + frame_) % far_every_ == 0;
  }

 private:
  const TsdfVolume& volume_;
  FrameConstants constants_;
  Eigen::Matrix3f rotation_;  // world to camera
  Eigen::Vector3f translation_, half_block_;
  float far_depth_;
  int far_every_, frame_;
};

}  // namespace glint::fusion
