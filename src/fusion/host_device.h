#pragma once
// GLINT_HOST_DEVICE marks the small per-voxel / per-pixel functions that the CPU loops call and
// that a CUDA kernel (GLINT_WITH_CUDA) can call too.
#if defined(__CUDACC__)
#define GLINT_HOST_DEVICE __host__ __device__
#else
#define GLINT_HOST_DEVICE
#endif
