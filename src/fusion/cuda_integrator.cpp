#include "fusion/cuda_integrator.h"

#include "core/error.h"
#if defined(GLINT_WITH_CUDA)
#include <vector>

#include "fusion/cuda_device_pools.h"
#include "fusion/integrate_frame.h"
#endif

namespace glint::fusion {

#if defined(GLINT_WITH_CUDA)

namespace {

// The volume's host pools at block 0, in CudaDevicePools' order of fields.
CudaDevicePools::HostPools host_pools(TsdfVolume& volume) {
  if (!volume.has_colour()) return {volume.sdf_m(0), volume.weight(0)};
  return {volume.sdf_m(0), volume.weight(0), {volume.red(0), volume.green(0), volume.blue(0)}};
}

}  // namespace

struct CudaIntegrator::Device {
  explicit Device(TsdfVolume& volume) : pools(host_pools(volume), volume.params().block_capacity) {}
  CudaDevicePools pools;
  std::vector<int> fused;  // this frame's fused blocks and their origins
  std::vector<float> origins;
};

bool CudaIntegrator::available() { return CudaDevicePools::device_present(); }

CudaIntegrator::CudaIntegrator(TsdfVolume& volume) : device_(std::make_unique<Device>(volume)) {
  device_->pools.mirror(volume.block_count(), /*upload=*/true);
}

CudaIntegrator::~CudaIntegrator() = default;

void CudaIntegrator::integrate_blocks(TsdfVolume& volume, const VisibleBlocks& visible,
                                      const ImageF& depth_m, const ImageF& colour,
                                      const Intrinsics& intrinsics, const Pose& camera_to_world) {
  if (volume.sdf_m(0) != device_->pools.host_sdf())
    throw Error("CUDA", "integrate_blocks", "not the volume this integrator was made for");
  const FrameIntegration frame(volume, visible, depth_m, colour, intrinsics, camera_to_world);
  Device& device = *device_;
  // Blocks allocated since the last frame are zero on the host.
  device.pools.mirror(volume.block_count(), /*upload=*/false);
  device.fused.clear();
  device.origins.clear();
  for (const int block : visible.indices) {
    const Eigen::Vector3f origin = frame.block_origin(block);
    if (!frame.fused_now(block, origin)) continue;
    volume.count_fusion(block);
    device.fused.push_back(block);
    device.origins.insert(device.origins.end(), origin.data(), origin.data() + 3);
  }
  device.pools.fuse(frame.constants(), colour.empty() ? nullptr : colour.plane(0),
                    device.fused.data(), device.origins.data(), device.fused.size());
}

#else  // a build without CUDA: the integrator reports that it cannot run

struct CudaIntegrator::Device {};

bool CudaIntegrator::available() { return false; }

CudaIntegrator::CudaIntegrator(TsdfVolume&) {
  throw Error("CUDA", "",
              "this glint was built without CUDA (configure with -DGLINT_WITH_CUDA=ON)");
}

CudaIntegrator::~CudaIntegrator() = default;

void CudaIntegrator::integrate_blocks(TsdfVolume&, const VisibleBlocks&, const ImageF&,
                                      const ImageF&, const Intrinsics&, const Pose&) {}

#endif

}  // namespace glint::fusion
