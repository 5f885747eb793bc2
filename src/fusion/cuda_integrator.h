#pragma once
// CudaIntegrator: TSDF integration (integrate_blocks) on a CUDA GPU, for builds configured with
// GLINT_WITH_CUDA=ON. The block hash, block allocation (allocate_blocks) and the count of each
// block's fusions stay on the host; the GPU keeps a copy of the voxel pools and fuses each
// frame's blocks there, one thread per voxel, with the CPU kernel's per-voxel maths
// (tsdf_kernels.h). The host pools are pinned and every voxel that takes an observation is
// written through to them, so after each frame the volume on the host is what
// fusion::integrate_blocks() would have made of it (up to float rounding), and its readers (ray
// casting, meshing, the reflectance pipeline's observations) need no copy back.
//
// The volume must outlive the integrator, and while the integrator fuses it, nothing else may
// write its voxels (the GPU's copy would go stale).
#include <memory>

#include "core/camera.h"
#include "core/image.h"
#include "fusion/integrate.h"
#include "fusion/tsdf_volume.h"

namespace glint::fusion {

class CudaIntegrator {
 public:
  // Whether this build has CUDA and a CUDA device is present.
  static bool available();

  // Copies the volume's blocks to the GPU and pins its host pools. Throws glint::Error when the
  // build has no CUDA, no device is present, or the GPU's memory is short.
  explicit CudaIntegrator(TsdfVolume& volume);
  ~CudaIntegrator();
  CudaIntegrator(const CudaIntegrator&) = delete;
  CudaIntegrator& operator=(const CudaIntegrator&) = delete;

  // integrate_blocks() on the GPU, with the same contract and result (up to float rounding),
  // into the volume this integrator was made for.
  void integrate_blocks(TsdfVolume& volume, const VisibleBlocks& visible, const ImageF& depth_m,
                        const ImageF& colour, const Intrinsics& intrinsics,
                        const Pose& camera_to_world);

 private:
  struct Device;
  std::unique_ptr<Device> device_;
};

}  // namespace glint::fusion
