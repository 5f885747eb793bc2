#pragma once
// TsdfSampler: reads the TSDF at arbitrary world points (nearest voxel or trilinear), caching
// the blocks last looked up (rays and neighbouring samples mostly stay in a few blocks). One
// sampler per thread; the volume must not change while it is read.
#include <Eigen/Core>
#include <array>
#include <climits>
#include <cmath>

#include "fusion/block_index_cache.h"
#include "fusion/block_occupancy.h"
#include "fusion/tsdf_volume.h"

namespace glint::fusion {

class TsdfSampler {
 public:
  // With `occupancy` (of this volume, built after its last allocation), blocks it rules out are
  // not looked up in the block hash.
  explicit TsdfSampler(const TsdfVolume& volume, const BlockOccupancy* occupancy = nullptr)
      : volume_(volume),
        occupancy_(occupancy),
        inverse_voxel_(1.0f / float(volume.params().voxel_size_m)) {}

  enum class Sample { unallocated, unobserved, observed };

  // Nearest voxel to world point p.
  Sample nearest(const Eigen::Vector3f& p, float& sdf_m) {
    const Eigen::Vector3f v = p * inverse_voxel_;
    return voxel(round_to_int(v.x()), round_to_int(v.y()), round_to_int(v.z()), sdf_m);
  }

  // Trilinear interpolation of the 8 voxels around p; false when any of them is unobserved.
  bool trilinear(const Eigen::Vector3f& p, float& sdf_m) {
    const Eigen::Vector3f v = p * inverse_voxel_;
    const int x = int(std::floor(v.x())), y = int(std::floor(v.y())), z = int(std::floor(v.z()));
    float cell[2][2][2];
    if (!read_box(
            x, y, z, [](int, int, int) { return true; }, cell))
      return false;
    float corner[8];
    for (int c = 0; c < 8; ++c) corner[c] = cell[c & 1][(c >> 1) & 1][(c >> 2) & 1];
    sdf_m = interpolate(corner, v.x() - x, v.y() - y, v.z() - z);
    return true;
  }

  // The trilinear value at p and its central-difference gradient (per metre) with a step of one
  // voxel, i.e. trilinear() at p and at p +- one voxel along each axis. The seven stencils share
  // 32 voxels, each read once; false when any of them is unobserved.
  bool trilinear_with_gradient(const Eigen::Vector3f& p, float& sdf_m, Eigen::Vector3f& gradient) {
    const Eigen::Vector3f v = p * inverse_voxel_;
    const int x = int(std::floor(v.x())), y = int(std::floor(v.y())), z = int(std::floor(v.z()));
    // stencil[a][b][c] = voxel (x + a - 1, y + b - 1, z + c - 1): the 2x2x2 cell around p
    // (indices 1, 2) and its six face neighbours (one index 0 or 3).
    float stencil[4][4][4];
    const auto in_stencil = [](int a, int b, int c) {
      return (a == 0 || a == 3) + (b == 0 || b == 3) + (c == 0 || c == 3) <= 1;
    };
    if (!read_box(x - 1, y - 1, z - 1, in_stencil, stencil)) return false;
    const float fx = v.x() - x, fy = v.y() - y, fz = v.z() - z;
    const auto at = [&](int dx, int dy, int dz) {
      float corner[8];
      for (int k = 0; k < 8; ++k)
        corner[k] = stencil[1 + dx + (k & 1)][1 + dy + ((k >> 1) & 1)][1 + dz + ((k >> 2) & 1)];
      return interpolate(corner, fx, fy, fz);
    };
    sdf_m = at(0, 0, 0);
    const float inverse_step = 0.5f * inverse_voxel_;
    gradient = Eigen::Vector3f(at(1, 0, 0) - at(-1, 0, 0), at(0, 1, 0) - at(0, -1, 0),
                               at(0, 0, 1) - at(0, 0, -1)) *
               inverse_step;
    return true;
  }

  // Around a point p whose nearest voxel lies in an unallocated block: the world box [low, high)
  // that surely holds no allocated block (BlockOccupancy::empty_region; without an occupancy,
  // the block alone), infinite where it is unbounded. Voxel x covers [x - 1/2, x + 1/2) voxels.
  void empty_box(const Eigen::Vector3f& p, Eigen::Vector3f& low, Eigen::Vector3f& high) const {
    const Eigen::Vector3f v = p * inverse_voxel_;
    const Eigen::Vector3i block(round_to_int(v.x()) >> kBlockShift,
                                round_to_int(v.y()) >> kBlockShift,
                                round_to_int(v.z()) >> kBlockShift);
    Eigen::Vector3i first = block, last = block;
    if (occupancy_) occupancy_->empty_region(block.x(), block.y(), block.z(), first, last);
    const float voxel = 1.0f / inverse_voxel_;
    for (int axis = 0; axis < 3; ++axis) {
      low[axis] =
          first[axis] == INT_MIN ? -INFINITY : (float(first[axis]) * kBlockSide - 0.5f) * voxel;
      high[axis] =
          last[axis] == INT_MAX ? INFINITY : (float(last[axis] + 1) * kBlockSide - 0.5f) * voxel;
    }
  }

  // Colour of the nearest voxel (call after an observed sample there); black in a volume that
  // keeps no colour.
  Eigen::Vector3f nearest_colour(const Eigen::Vector3f& p) {
    if (!volume_.has_colour()) return Eigen::Vector3f::Zero();
    const Eigen::Vector3f v = p * inverse_voxel_;
    float unused;
    const int x = round_to_int(v.x()), y = round_to_int(v.y()), z = round_to_int(v.z());
    if (voxel(x, y, z, unused) != Sample::observed) return Eigen::Vector3f::Zero();
    const int index = voxel_in_block(x, y, z);
    const int block = cached_block(x >> kBlockShift, y >> kBlockShift, z >> kBlockShift);
    return {volume_.red(block)[index], volume_.green(block)[index], volume_.blue(block)[index]};
  }

  // Global voxel coordinates -> its sample.
  Sample voxel(int x, int y, int z, float& sdf_m) {
    const int block = cached_block(x >> kBlockShift, y >> kBlockShift, z >> kBlockShift);
    if (block < 0) return Sample::unallocated;
    const int index = voxel_in_block(x, y, z);
    const float sdf = volume_.sdf_m(block)[index];
    if (!observed(sdf)) return Sample::unobserved;
    sdf_m = sdf;
    return Sample::observed;
  }

 private:
  // Corners indexed by bits (x, y, z) = (1, 2, 4), at fractional position (fx, fy, fz).
  static float interpolate(const float corner[8], float fx, float fy, float fz) {
    const auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    return lerp(lerp(lerp(corner[0], corner[1], fx), lerp(corner[2], corner[3], fx), fy),
                lerp(lerp(corner[4], corner[5], fx), lerp(corner[6], corner[7], fx), fy), fz);
  }
  static int round_to_int(float value) { return static_cast<int>(std::floor(value + 0.5f)); }
  // Reads voxel (x0 + a, y0 + b, z0 + c) into box[a][b][c] for each (a, b, c) that wanted()
  // names; false when one of them is unallocated or unobserved. A box of at most a block's side
  // spans at most two blocks along each axis: their (at most 8) look-ups are made once, and each
  // voxel is then read at its offset in its block (per voxel, a cache look-up was most of the
  // cost of the ray cast's and the surface refreshes' reads).
  template <int kSpan, class Wanted>
  bool read_box(int x0, int y0, int z0, Wanted wanted, float (&box)[kSpan][kSpan][kSpan]) {
    static_assert(kSpan <= kBlockSide);
    constexpr int last = kBlockSide - 1;
    // Per axis and position: which of the two blocks (0, 1), and the voxel's offset in it.
    int side_x[kSpan], side_y[kSpan], side_z[kSpan], offset_x[kSpan], offset_y[kSpan],
        offset_z[kSpan];
    for (int i = 0; i < kSpan; ++i) {
      side_x[i] = ((x0 + i) >> kBlockShift) - (x0 >> kBlockShift);
      side_y[i] = ((y0 + i) >> kBlockShift) - (y0 >> kBlockShift);
      side_z[i] = ((z0 + i) >> kBlockShift) - (z0 >> kBlockShift);
      offset_x[i] = (x0 + i) & last;
      offset_y[i] = ((y0 + i) & last) * kBlockSide;
      offset_z[i] = ((z0 + i) & last) * kBlockSide * kBlockSide;
    }
    const float* blocks[2][2][2];
    for (int c = 0; c <= side_z[kSpan - 1]; ++c)
      for (int b = 0; b <= side_y[kSpan - 1]; ++b)
        for (int a = 0; a <= side_x[kSpan - 1]; ++a) {
          const int block = cached_block((x0 >> kBlockShift) + a, (y0 >> kBlockShift) + b,
                                         (z0 >> kBlockShift) + c);
          blocks[a][b][c] = block < 0 ? nullptr : volume_.sdf_m(block);
        }
    for (int a = 0; a < kSpan; ++a)
      for (int b = 0; b < kSpan; ++b)
        for (int c = 0; c < kSpan; ++c) {
          if (!wanted(a, b, c)) continue;
          const float* block = blocks[side_x[a]][side_y[b]][side_z[c]];
          if (!block) return false;
          box[a][b][c] = block[offset_z[c] + offset_y[b] + offset_x[a]];
          if (!observed(box[a][b][c])) return false;
        }
    return true;
  }

  // The pool index of block (bx, by, bz), or -1. A stencil of a few voxels spans at most two
  // blocks along each axis: a cache of two per axis holds all eight, where a single entry was
  // looked up again at every crossing.
  int cached_block(int bx, int by, int bz) {
    return blocks_({bx, by, bz}, [&](const Eigen::Vector3i& block) {
      return occupancy_ && !occupancy_->may_hold(block.x(), block.y(), block.z())
                 ? VoxelBlockHash::kAbsent
                 : volume_.hash().find(block);
    });
  }

  const TsdfVolume& volume_;
  const BlockOccupancy* occupancy_;
  float inverse_voxel_;
  BlockIndexCache<2> blocks_;
};

}  // namespace glint::fusion
