#pragma once
// Per-voxel and per-ray maths of TSDF fusion, as small inline functions that the TBB loops and
// the CUDA kernel (cuda_device_pools.cu) call (no allocation, no exceptions).
#include <cmath>

#include "fusion/host_device.h"

namespace glint::fusion {

// Weighted running average of one voxel with one projective observation (Curless & Levoy 1996;
// VoxelHashing §4.2): measured_sdf_m = depth - z along the optical axis. Observations more than
// `truncation_m` behind the surface, and those not `valid`, are ignored (`fused` false); in
// front they are clamped. A voxel's first fusion starts from weight 0 and kUnobservedSdf, which
// the product sdf_m * weight turns into 0 (tsdf_volume.h). Written without branches so that T may
// be a GCC vector of voxels (Mask then holds all-ones lanes for true); T = float, Mask = bool is
// the scalar rule. Arguments by reference: a vector by value changes the calling convention between
// the AVX2 clone and the baseline.
template <class T, class Mask>
GLINT_HOST_DEVICE inline void fuse_voxel(const T& measured_sdf_m, const T& truncation_m,
                                         float max_weight, const Mask& valid, T& sdf_m, T& weight,
                                         Mask& fused) {
  fused = valid & (measured_sdf_m >= -truncation_m);
  const T observation = measured_sdf_m < truncation_m ? measured_sdf_m : truncation_m;
  const T total = weight + 1.0f;
  sdf_m = fused ? (sdf_m * weight + observation) / total : sdf_m;
  weight = fused ? (total < max_weight ? total : T{} + max_weight) : weight;
}

// The same running average for a colour channel; `weight_before` is the voxel's weight before
// fuse_voxel() updated it. By the reciprocal, which the three channels of a voxel share where
// they are inlined together: three divisions were a sixth of a colour frame's integration.
GLINT_HOST_DEVICE inline float fuse_colour(float mean, float weight_before, float observation) {
  return (mean * weight_before + observation) * (1.0f / (weight_before + 1.0f));
}

// One frame's integration constants, in camera coordinates (plain data: the CUDA kernel gets a
// copy with `depth` pointing into device memory).
struct FrameConstants {
  float fx, fy, cx, cy;
  int width, height;
  float depth_min, depth_max, truncation_m, truncation_per_depth, max_weight;
  const float* depth;
  // One voxel step along the volume's x, y and z axes, in camera coordinates.
  float step_x[3], step_y[3], step_z[3];
};

// Nearest pixel of a projected point, or false when it falls outside a width x height image.
GLINT_HOST_DEVICE inline bool nearest_pixel(float u, float v, int width, int height, int& x,
                                            int& y) {
  if (!(u >= -0.5f && v >= -0.5f && u < width - 0.5f && v < height - 0.5f)) return false;
  x = static_cast<int>(u + 0.5f);
  y = static_cast<int>(v + 0.5f);
  return true;
}

// Fuses the voxel at camera coordinates (x, y, z) with the depth under its nearest pixel: the
// scalar form of the CPU's row kernel (integrate.cpp), one voxel per CUDA thread. Returns the
// pixel it took its observation from, or -1 where it took none.
GLINT_HOST_DEVICE inline int fuse_voxel_projective(const FrameConstants& k, float x, float y,
                                                   float z, float& sdf_m, float& weight) {
  const float inverse_z = 1.0f / z;
  int column = 0, row = 0;
  const bool inside =
      z > 0 && nearest_pixel(k.fx * x * inverse_z + k.cx, k.fy * y * inverse_z + k.cy, k.width,
                             k.height, column, row);
  const int pixel = inside ? row * k.width + column : 0;
  const float d = inside ? k.depth[pixel] : 0.0f;
  bool fused = false;
  fuse_voxel(d - z, k.truncation_m + k.truncation_per_depth * d, k.max_weight,
             inside && d >= k.depth_min && d <= k.depth_max, sdf_m, weight, fused);
  return fused ? pixel : -1;
}

// Calls visit(bx, by, bz) for every cell of a grid of side `cell` that the segment a -> b
// crosses, in order (Amanatides & Woo 1987). Coordinates in metres.
template <class Visit>
GLINT_HOST_DEVICE inline void for_each_cell_on_segment(const float a[3], const float b[3],
                                                       float cell, Visit&& visit) {
  int index[3], step[3], end[3];
  float t_max[3], t_delta[3];
  for (int i = 0; i < 3; ++i) {
    index[i] = static_cast<int>(std::floor(a[i] / cell));
    end[i] = static_cast<int>(std::floor(b[i] / cell));
    const float direction = b[i] - a[i];
    step[i] = direction > 0 ? 1 : (direction < 0 ? -1 : 0);
    if (step[i] == 0) {
      t_max[i] = t_delta[i] = INFINITY;
      continue;
    }
    const float boundary = (index[i] + (step[i] > 0 ? 1 : 0)) * cell;
    t_max[i] = (boundary - a[i]) / direction;
    t_delta[i] = cell / std::fabs(direction);
  }
  const int cells =
      std::abs(end[0] - index[0]) + std::abs(end[1] - index[1]) + std::abs(end[2] - index[2]);
  for (int n = 0; n <= cells; ++n) {
    visit(index[0], index[1], index[2]);
    const int axis =
        t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    index[axis] += step[axis];
    t_max[axis] += t_delta[axis];
  }
}

}  // namespace glint::fusion
