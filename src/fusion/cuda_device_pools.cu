#include <cuda_runtime.h>

#include <algorithm>
#include <string>

#include "core/error.h"
#include "fusion/cuda_device_pools.h"

namespace glint::fusion {
namespace {

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess)
    throw Error("CUDA", what,
                std::string(cudaGetErrorName(status)) + ": " + cudaGetErrorString(status));
}

void release(void* device_pointer) {
  if (device_pointer) cudaFree(device_pointer);
}

// The device buffer `buffer` with room for `size` elements, grown by half at least.
template <class T>
T* grown(T*& buffer, std::size_t& capacity, std::size_t size) {
  if (size <= capacity) return buffer;
  const std::size_t elements = std::max(size, capacity + capacity / 2);
  release(buffer);
  buffer = nullptr;
  capacity = 0;
  check(cudaMalloc(&buffer, elements * sizeof(T)), "device memory");
  capacity = elements;
  return buffer;
}

constexpr std::size_t kPinnedChunkBlocks = 1024;

// One side's pools, typed (CudaDevicePools keeps them as bytes).
struct FieldPointers {
  float* sdf;
  std::uint8_t* weight;
  float* colour[3];

  FieldPointers(char* const* fields, int count)
      : sdf(reinterpret_cast<float*>(fields[0])),
        weight(reinterpret_cast<std::uint8_t*>(fields[1])),
        colour{} {
    for (int c = 0; c + 2 < count; ++c) colour[c] = reinterpret_cast<float*>(fields[2 + c]);
  }
};

// One CUDA block per TSDF block, one thread per voxel (voxel = (z * 8 + y) * 8 + x), so that a
// warp reads and writes 32 consecutive floats of each pool. Voxels that take no observation
// keep their values on both sides and are not written: the host pools are reached over PCIe.
// `colour` is null for a frame fused without colour.
__global__ void fuse_blocks(FrameConstants k, FieldPointers device, FieldPointers host,
                            const float* colour, const int* blocks, const float* origins) {
  const int v = threadIdx.x;
  const int x = v & (kBlockSide - 1), y = (v / kBlockSide) & (kBlockSide - 1),
            z = v / (kBlockSide * kBlockSide);
  const float* origin = origins + 3 * blockIdx.x;
  float p[3];
  for (int axis = 0; axis < 3; ++axis)  // in the CPU row kernel's order of operations
    p[axis] = origin[axis] + k.step_z[axis] * float(z) + k.step_y[axis] * float(y) +
              float(x) * k.step_x[axis];
  const std::size_t voxel = std::size_t(blocks[blockIdx.x]) * kVoxelsPerBlock + v;
  float sdf = device.sdf[voxel], weight = float(device.weight[voxel]);
  const float weight_before = weight;
  const int pixel = fuse_voxel_projective(k, p[0], p[1], p[2], sdf, weight);
  if (pixel < 0) return;
  device.sdf[voxel] = host.sdf[voxel] = sdf;
  device.weight[voxel] = host.weight[voxel] = std::uint8_t(weight);  // a whole number <= 255
  if (!colour) return;
  const std::size_t plane = std::size_t(k.width) * k.height;
  for (int c = 0; c < 3; ++c) {
    const float mean =
        fuse_colour(device.colour[c][voxel], weight_before, colour[c * plane + pixel]);
    device.colour[c][voxel] = host.colour[c][voxel] = mean;
  }
}

}  // namespace

bool CudaDevicePools::device_present() {
  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no driver" status
    return false;
  }
  return devices > 0;
}

CudaDevicePools::CudaDevicePools(const HostPools& host, std::size_t capacity_blocks)
    : fields_(host.colour[0] ? 5 : 2), capacity_blocks_(capacity_blocks) {
  if (!device_present()) throw Error("CUDA", "", "no CUDA device is present (or no driver for it)");
  host_[0] = reinterpret_cast<char*>(host.sdf);
  voxel_bytes_[0] = sizeof(float);
  host_[1] = reinterpret_cast<char*>(host.weight);
  voxel_bytes_[1] = sizeof(std::uint8_t);
  for (int f = 2; f < fields_; ++f) {
    host_[f] = reinterpret_cast<char*>(host.colour[f - 2]);
    voxel_bytes_[f] = sizeof(float);
  }
}

CudaDevicePools::~CudaDevicePools() {
  for (void* range : pinned_) cudaHostUnregister(range);
  for (char* pool : pools_) release(pool);
  release(depth_);
  release(colour_);
  release(blocks_);
  release(origins_);
}

void CudaDevicePools::pin_host(std::size_t blocks) {
  while (pinned_blocks_ < blocks) {
    const std::size_t first = pinned_blocks_;
    const std::size_t count = std::min(kPinnedChunkBlocks, capacity_blocks_ - first);
    for (int f = 0; f < fields_; ++f) {
      void* range = host_[f] + first * block_bytes(f);
      check(cudaHostRegister(range, count * block_bytes(f), cudaHostRegisterMapped),
            "pinning the host's voxel pools");
      pinned_.push_back(range);
      void* on_device = nullptr;
      check(cudaHostGetDevicePointer(&on_device, range, 0), "mapping the host's voxel pools");
      if (on_device != range)
        throw Error("CUDA", "host memory",
                    "the GPU does not address pinned host memory at its host address (no "
                    "unified addressing)");
    }
    pinned_blocks_ = first + count;
  }
}

void CudaDevicePools::mirror(std::size_t blocks, bool upload) {
  if (blocks <= mirrored_) return;
  pin_host(blocks);
  if (blocks > device_blocks_) {
    const std::size_t room = std::min(capacity_blocks_, std::max(blocks, 2 * device_blocks_));
    for (int f = 0; f < fields_; ++f) {
      char* pool = nullptr;
      const cudaError_t status = cudaMalloc(&pool, room * block_bytes(f));
      if (status != cudaSuccess)
        throw Error("CUDA", "device memory",
                    "no room for " + std::to_string(room) + " TSDF blocks (" +
                        std::to_string(room * block_bytes(f) >> 20) +
                        " MiB for one of their pools): " + cudaGetErrorString(status));
      if (mirrored_)
        check(cudaMemcpy(pool, pools_[f], mirrored_ * block_bytes(f), cudaMemcpyDeviceToDevice),
              "growing the voxel pools");
      release(pools_[f]);
      pools_[f] = pool;
    }
    device_blocks_ = room;
  }
  // Chunk by chunk: a copy may not span two pinned ranges.
  for (std::size_t first = mirrored_; first < blocks;) {
    const std::size_t end = std::min(blocks, (first / kPinnedChunkBlocks + 1) * kPinnedChunkBlocks);
    for (int f = 0; f < fields_; ++f) {
      const std::size_t offset = first * block_bytes(f), bytes = (end - first) * block_bytes(f);
      check(upload
                ? cudaMemcpy(pools_[f] + offset, host_[f] + offset, bytes, cudaMemcpyHostToDevice)
                : cudaMemset(pools_[f] + offset, 0, bytes),
            "mirroring new blocks");
    }
    first = end;
  }
  mirrored_ = blocks;
}

void CudaDevicePools::fuse(const FrameConstants& k, const float* colour, const int* blocks,
                           const float* origins, std::size_t count) {
  if (count == 0) return;
  const std::size_t pixels = std::size_t(k.width) * k.height;
  FrameConstants on_device = k;
  on_device.depth = grown(depth_, depth_capacity_, pixels);
  check(cudaMemcpy(depth_, k.depth, pixels * sizeof(float), cudaMemcpyHostToDevice),
        "uploading the depth image");
  if (colour)
    check(cudaMemcpy(grown(colour_, colour_capacity_, 3 * pixels), colour,
                     3 * pixels * sizeof(float), cudaMemcpyHostToDevice),
          "uploading the colour image");
  check(cudaMemcpy(grown(blocks_, blocks_capacity_, count), blocks, count * sizeof(int),
                   cudaMemcpyHostToDevice),
        "uploading the block list");
  check(cudaMemcpy(grown(origins_, origins_capacity_, 3 * count), origins,
                   3 * count * sizeof(float), cudaMemcpyHostToDevice),
        "uploading the block origins");
  const FieldPointers device(pools_, fields_), host(host_, fields_);
  fuse_blocks<<<unsigned(count), kVoxelsPerBlock>>>(on_device, device, host,
                                                    colour ? colour_ : nullptr, blocks_, origins_);
  check(cudaGetLastError(), "launching the fusion kernel");
  check(cudaDeviceSynchronize(), "fusing blocks");
}

}  // namespace glint::fusion
