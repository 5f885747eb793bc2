#include "fusion/raycast.h"

#include <fmt/format.h>

#include <array>
#include <atomic>
#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "fusion/depth_maps.h"
#include "fusion/ray_march.h"
#include "fusion/tsdf_sampler.h"

namespace glint::fusion {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kTilePx = 4;

// Per 4x4-pixel tile, the camera-depth interval that allocated blocks cover (the union of their
// projected bounding boxes), so rays skip the empty space in front of and behind the model
// (smaller tiles than 8x8 let rays start nearer the surface).
// Depths are positive floats kept as their bit patterns, which order like the values.
class TileDepthRanges {
 public:
  TileDepthRanges(const TsdfVolume& volume, const Intrinsics& k, const Pose& camera_to_world)
      : tiles_x_((k.width + kTilePx - 1) / kTilePx),
        near_(std::size_t(tiles_x_) * ((k.height + kTilePx - 1) / kTilePx)),
        far_(near_.size()) {
    for (std::size_t i = 0; i < near_.size(); ++i) {
      near_[i].store(std::bit_cast<std::uint32_t>(std::numeric_limits<float>::max()));
      far_[i].store(0);
    }
    const VolumeParams& params = volume.params();
    const Pose world_to_camera = camera_to_world.inverse();
    const double block = params.block_size_m();
    const int tiles_y = int(near_.size()) / tiles_x_;
    parallel_for(volume.block_count(), [&](std::size_t b) {
      const Eigen::Vector3d origin = volume.block_origin_m(volume.hash().block(int(b)));
      Eigen::Vector2d low(1e30, 1e30), high(-1e30, -1e30);
      double z_min = 1e30, z_max = -1e30;
      Eigen::Vector3d corners[8];
      for (int c = 0; c < 8; ++c) {
        corners[c] =
            world_to_camera * (origin + block * Eigen::Vector3d(c & 1, (c >> 1) & 1, (c >> 2) & 1));
        z_min = std::min(z_min, corners[c].z());
        z_max = std::max(z_max, corners[c].z());
      }
      if (z_max < params.depth_min_m || z_min > params.depth_max_m) return;
      // The projected bounding box of the block's part beyond the near plane z = depth_min (rays
      // start there): its corners beyond it and where its edges cross it. (Counting a block that
      // straddles the plane as covering every tile made every ray of the frame start at the
      // near plane: bunnies, 90-150 such blocks in a third of the views.)
      const auto cover = [&](const Eigen::Vector3d& point) {
        const Eigen::Vector2d uv = k.project(point);
        low = low.cwiseMin(uv);
        high = high.cwiseMax(uv);
      };
      for (int c = 0; c < 8; ++c) {
        if (corners[c].z() >= params.depth_min_m) cover(corners[c]);
        for (int axis = 1; axis < 8; axis <<= 1) {
          if (c & axis) continue;
          const Eigen::Vector3d &a = corners[c], &b = corners[c | axis];
          if ((a.z() < params.depth_min_m) != (b.z() < params.depth_min_m))
            cover(a + (b - a) * ((params.depth_min_m - a.z()) / (b.z() - a.z())));
        }
      }
      const int x0 = std::max(0, int(std::floor((low.x() + 0.5) / kTilePx)));
      const int y0 = std::max(0, int(std::floor((low.y() + 0.5) / kTilePx)));
      const int x1 = std::min(tiles_x_ - 1, int(std::floor((high.x() + 0.5) / kTilePx)));
      const int y1 = std::min(tiles_y - 1, int(std::floor((high.y() + 0.5) / kTilePx)));
      const auto near = std::bit_cast<std::uint32_t>(float(std::max(z_min, params.depth_min_m)));
      const auto far = std::bit_cast<std::uint32_t>(float(z_max));
      for (int ty = y0; ty <= y1; ++ty)
        for (int tx = x0; tx <= x1; ++tx) {
          const std::size_t tile = std::size_t(ty) * tiles_x_ + tx;
          for (auto value = near_[tile].load();
               near < value && !near_[tile].compare_exchange_weak(value, near);) {
          }
          for (auto value = far_[tile].load();
               far > value && !far_[tile].compare_exchange_weak(value, far);) {
          }
        }
    });
  }

  // The interval of pixel (x, y); empty (near > far) when no block projects there.
  void interval(int x, int y, float& near, float& far) const {
    const std::size_t tile = std::size_t(y / kTilePx) * tiles_x_ + x / kTilePx;
    near = std::bit_cast<float>(near_[tile].load(std::memory_order_relaxed));
    far = std::bit_cast<float>(far_[tile].load(std::memory_order_relaxed));
  }

 private:
  int tiles_x_;
  std::vector<std::atomic<std::uint32_t>> near_, far_;
};

// How far in front of a hinted depth (voxels) a ray starts first: the model's surface lies
// within depth noise of the depth just fused, and from there two trilinear samples usually
// bracket it, where the band's front edge took one or two nearest-voxel steps more.
constexpr float kHintLead = 2;

// One pixel's ray and its marches in turn until one finds the surface. With a hint d (the depth
// just fused there), first from kHintLead voxels in front of d, where the model's surface lies;
// where that start is already behind the surface, from the truncation band's front edge
// d - t(d), in front of the surface inside the space the frame's voxels cover; and, where
// neither finds it, from the tile's near depth.
class PixelCast {
 public:
  // Starts pixel (x, y); false when no allocated block projects there, or when only hinted
  // pixels are cast and it has no hint.
  bool begin(int x, int y, const TileDepthRanges& ranges, const Intrinsics& intrinsics,
             const Eigen::Matrix3f& rotation, const VolumeParams& params,
             const RaycastOptions& options) {
    float far;
    ranges.interval(x, y, near_, far);
    if (near_ > far) return false;
    const float hint = options.depth_hint ? options.depth_hint->at(x, y, 0) : 0.0f;
    if (options.hinted_pixels_only && options.depth_hint && !(hint > 0)) return false;
    x_ = x;
    ray_ = rotation * intrinsics.ray(x, y).cast<float>();
    const float voxel = float(params.voxel_size_m);
    march_ = RayMarch(ray_, far, voxel);
    band_start_ = hint - float(params.truncation_at(hint));
    if (hint > 0 && band_start_ > near_) {
      const float lead_start = std::max(band_start_, hint - kHintLead * voxel);
      march_.start(lead_start);
      phase_ = lead_start > band_start_ ? Phase::lead : Phase::band;
    } else {
      march_.start(near_);
      phase_ = Phase::tile;
    }
    return true;
  }

  // One sample; false once the pixel is done (hit() then says where, 0 = no surface).
  bool step(TsdfSampler& sampler, const Eigen::Vector3f& origin) {
    if (march_.step(sampler, origin, ray_)) return true;
    const MarchEnd& end = march_.end();
    if (end.t > 0 || phase_ == Phase::tile) return false;
    if (phase_ == Phase::lead && end.back_face) {
      march_.start(band_start_);
      phase_ = Phase::band;
    } else {
      march_.start(near_);
      phase_ = Phase::tile;
    }
    return true;
  }

  int x() const { return x_; }
  const Eigen::Vector3f& ray() const { return ray_; }
  float hit() const { return march_.end().t; }

 private:
  enum class Phase { lead, band, tile };
  int x_ = 0;
  Eigen::Vector3f ray_;
  float near_ = 0, band_start_ = 0;
  Phase phase_ = Phase::tile;
  RayMarch march_;
};

// Rays a thread advances in turn (see RayMarch).
constexpr int kRaysInFlight = 4;

// Casts row y's rays into `view` (its colour only where the view has colour), kRaysInFlight at a
// time. Also compiled for x86-64-v3 (one-instruction rounding, fused multiply-adds, so the last
// bits of a hit differ from the baseline build's). Interleaved rays overlap their chains of
// dependent loads; the clone pays only with them.
// clang-14 (the fuzz build) refuses flatten on a multiversioned function; there the inliner
// decides.
#if defined(__clang__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#else
__attribute__((target_clones("arch=x86-64-v3", "default"), flatten))
#endif
void cast_row(
    int y, const TsdfVolume& volume, const BlockOccupancy& occupancy, const TileDepthRanges& ranges,
    const Intrinsics& intrinsics, const Eigen::Matrix3f& rotation, const Eigen::Vector3f& origin,
    const RaycastOptions& options, SurfaceView& view) {
  const int width = intrinsics.width;
  const bool with_colour = !view.colour.empty();
  std::array<PixelCast, kRaysInFlight> casts;
  std::array<bool, kRaysInFlight> busy{};
  TsdfSampler sampler(volume, &occupancy);
  int next_x = 0, in_flight = 0;
  const auto start_next = [&](int lane) {
    while (next_x < width)
      if (casts[lane].begin(next_x++, y, ranges, intrinsics, rotation, volume.params(), options))
        return true;
    return false;
  };
  for (int lane = 0; lane < kRaysInFlight; ++lane) in_flight += busy[lane] = start_next(lane);
  while (in_flight > 0)
    for (int lane = 0; lane < kRaysInFlight; ++lane) {
      if (!busy[lane] || casts[lane].step(sampler, origin)) continue;
      const PixelCast& cast = casts[lane];
      const float t = cast.hit();
      if (t > 0) {
        const int x = cast.x();
        const Eigen::Vector3f p = origin + cast.ray() * t;
        view.depth_m.at(x, y, 0) = t;
        for (int c = 0; c < 3; ++c) view.points_m.at(x, y, c) = p[c];
        if (with_colour) {
          const Eigen::Vector3f rgb = sampler.nearest_colour(p);
          for (int c = 0; c < 3; ++c) view.colour.at(x, y, c) = rgb[c];
        }
      }
      if (!(busy[lane] = start_next(lane))) --in_flight;
    }
}

// Whether the central differences of normals_from_points() at (x, y) straddle a depth edge:
// a neighbour without a hit, or a second difference of depth above 1 % of it (a plane's depth
// has almost none; a silhouette's jumps by the gap between the surfaces).
bool at_depth_edge(const ImageF& depth, int x, int y) {
  if (x == 0 || y == 0 || x == depth.width() - 1 || y == depth.height() - 1) return true;
  const float z = depth.at(x, y, 0);
  const float left = depth.at(x - 1, y, 0), right = depth.at(x + 1, y, 0);
  const float up = depth.at(x, y - 1, 0), down = depth.at(x, y + 1, 0);
  if (!(left > 0 && right > 0 && up > 0 && down > 0)) return true;
  const float limit = 0.01f * z;
  return std::fabs(left + right - 2 * z) > limit || std::fabs(up + down - 2 * z) > limit;
}

}  // namespace

SurfaceView raycast(const TsdfVolume& volume, const Intrinsics& intrinsics,
                    const Pose& camera_to_world, const RaycastOptions& options) {
  if (const ImageF* depth_hint = options.depth_hint;
      depth_hint && (depth_hint->width() != intrinsics.width ||
                     depth_hint->height() != intrinsics.height || depth_hint->channels() != 1))
    throw Error("ray cast", "depth hint",
                fmt::format("expected {}x{} with 1 channel, got {}x{}x{}", intrinsics.width,
                            intrinsics.height, depth_hint->width(), depth_hint->height(),
                            depth_hint->channels()));
  const int width = intrinsics.width, height = intrinsics.height;
  SurfaceView view{ImageF(width, height, 1), ImageF(width, height, 3, kNaN), ImageF(),
                   options.colour ? ImageF(width, height, 3) : ImageF()};
  const Eigen::Matrix3f rotation = camera_to_world.linear().cast<float>();
  const Eigen::Vector3f origin = camera_to_world.translation().cast<float>();
  const TileDepthRanges ranges(volume, intrinsics, camera_to_world);
  const BlockOccupancy occupancy(volume);
  parallel_for(static_cast<std::size_t>(height), [&](std::size_t row) {
    cast_row(static_cast<int>(row), volume, occupancy, ranges, intrinsics, rotation, origin,
             options, view);
  });
  view.normals = normals_from_points(view.points_m, camera_to_world.translation());
  if (options.normals == RaycastNormals::from_gradient)
    parallel_for(static_cast<std::size_t>(height), [&](std::size_t row) {
      TsdfSampler sampler(volume);
      const int y = static_cast<int>(row);
      for (int x = 0; x < width; ++x) {
        if (!(view.depth_m.at(x, y, 0) > 0) || !at_depth_edge(view.depth_m, x, y)) continue;
        const Eigen::Vector3f p(view.points_m.at(x, y, 0), view.points_m.at(x, y, 1),
                                view.points_m.at(x, y, 2));
        float sdf;
        Eigen::Vector3f gradient;
        // Where a stencil voxel is unobserved, the points' normal stays.
        if (!sampler.trilinear_with_gradient(p, sdf, gradient) || !(gradient.norm() > 0)) continue;
        Eigen::Vector3f n = gradient.normalized();
        if (n.dot(origin - p) < 0) n = -n;
        for (int c = 0; c < 3; ++c) view.normals.at(x, y, c) = n[c];
      }
    });
  return view;
}

}  // namespace glint::fusion
