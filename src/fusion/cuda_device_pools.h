#pragma once
// The GPU side of CudaIntegrator (cuda_device_pools.cu): device copies of a TSDF volume's voxel
// pools, the host pools pinned so that the fusion kernel writes each changed voxel through to
// them, and that kernel. Plain types only, so that nvcc never compiles Eigen. Every call is
// synchronous and throws glint::Error naming the CUDA failure.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fusion/tsdf_kernels.h"
#include "fusion/volume_params.h"

namespace glint::fusion {

class CudaDevicePools {
 public:
  // Pool arrays per voxel, in this order: sdf, weight, and red, green, blue where kept.
  static constexpr int kMaxFields = 5;

  // Whether a CUDA device is present (false, not an error, without a driver).
  static bool device_present();

  // A volume's host pools at block 0 (TsdfVolume's types); colour all null where it keeps none.
  struct HostPools {
    float* sdf = nullptr;
    std::uint8_t* weight = nullptr;
    float* colour[3] = {};
  };

  // `host` holds `capacity_blocks` blocks per field and must outlive this object.
  CudaDevicePools(const HostPools& host, std::size_t capacity_blocks);
  ~CudaDevicePools();
  CudaDevicePools(const CudaDevicePools&) = delete;
  CudaDevicePools& operator=(const CudaDevicePools&) = delete;

  // Mirrors blocks [0, blocks): blocks not yet on the GPU are copied from the host (`upload`)
  // or, when the caller knows them to be zero (freshly allocated), zeroed.
  void mirror(std::size_t blocks, bool upload);
  // The host's distance pool (block 0).
  const float* host_sdf() const { return reinterpret_cast<const float*>(host_[0]); }

  // Fuses `count` blocks (pool indices `blocks`, each mirrored; `origins`, 3 floats per block,
  // the camera coordinates of each block's voxel (0, 0, 0)) with the host depth image k.depth
  // (k.width x k.height) and, where `colour` is not null, the host colour image (3 planes one
  // after the other, as ImageF keeps them). Each voxel that takes an observation is written to
  // the GPU's pools and to the host's.
  void fuse(const FrameConstants& k, const float* colour, const int* blocks, const float* origins,
            std::size_t count);

 private:
  // Pins the host pools of blocks [0, blocks), 1024 blocks (2 MiB of distances) at a time.
  void pin_host(std::size_t blocks);

  // Field f's bytes per block.
  std::size_t block_bytes(int f) const { return voxel_bytes_[f] * kVoxelsPerBlock; }

  int fields_ = 2;  // 5 with colour
  std::size_t capacity_blocks_;
  // Per field: the host pool, its bytes per voxel and the device pool, as bytes.
  char* host_[kMaxFields] = {};
  std::size_t voxel_bytes_[kMaxFields] = {};
  std::vector<void*> pinned_;  // registered host ranges
  std::size_t pinned_blocks_ = 0;
  std::size_t mirrored_ = 0;
  std::size_t device_blocks_ = 0;  // room in pools_
  char* pools_[kMaxFields] = {};
  // Per-frame input on the device, grown as needed.
  float* depth_ = nullptr;
  std::size_t depth_capacity_ = 0;
  float* colour_ = nullptr;
  std::size_t colour_capacity_ = 0;
  int* blocks_ = nullptr;
  std::size_t blocks_capacity_ = 0;
  float* origins_ = nullptr;
  std::size_t origins_capacity_ = 0;
};

}  // namespace glint::fusion
