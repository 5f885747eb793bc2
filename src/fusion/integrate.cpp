#include "fusion/integrate.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "core/cpu_level.h"
#include "core/error.h"
#include "core/parallel.h"
#include "fusion/integrate_frame.h"
#include "fusion/tsdf_kernels.h"
#include "fusion/vector_lanes.h"

namespace glint::fusion {
namespace {

void require_same_size(const ImageF& depth_m, const ImageF& colour, const Intrinsics& k) {
  if (depth_m.channels() != 1 || depth_m.width() != k.width || depth_m.height() != k.height)
    throw Error("depth image", "",
                fmt::format("expected {}x{} with 1 channel, got {}x{}x{}", k.width, k.height,
                            depth_m.width(), depth_m.height(), depth_m.channels()));
  if (!colour.empty() && (colour.channels() != 3 || !colour.same_size(depth_m)))
    throw Error("colour image", "",
                fmt::format("expected {}x{} with 3 channels, got {}x{}x{}", k.width, k.height,
                            colour.width(), colour.height(), colour.channels()));
}

}  // namespace

void allocate_blocks(TsdfVolume& volume, const ImageF& depth_m, const Intrinsics& intrinsics,
                     const Pose& camera_to_world, VisibleBlocks& visible) {
  require_same_size(depth_m, ImageF(), intrinsics);
  const VolumeParams& params = volume.params();
  const Eigen::Matrix3f rotation = camera_to_world.linear().cast<float>();
  const Eigen::Vector3f origin = camera_to_world.translation().cast<float>();
  const float block_size = static_cast<float>(params.block_size_m());
  const int width = depth_m.width();
  const std::size_t height = depth_m.height();
  const int stride = params.allocation_stride_px;
  const float* depth = depth_m.plane(0);
  const int frame = ++visible.frame;
  std::atomic<bool> pool_full{false};
  tbb::enumerable_thread_specific<std::vector<int>> found;

  tbb::enumerable_thread_specific<std::vector<Eigen::Vector3i>> buffers;
  const std::size_t rows = (depth_m.height() + stride - 1) / stride;
  parallel_for_chunks(rows, 4, [&](std::size_t row_begin, std::size_t row_end) {
    PendingBlocks pending(volume.hash(), buffers.local());
    for (std::size_t y = row_begin * stride; y < row_end * stride && y < height; y += stride) {
      for (int x = 0; x < width; x += stride) {
        const float d = depth[y * width + x];
        if (!(d >= params.depth_min_m && d <= params.depth_max_m)) continue;
        const float truncation = static_cast<float>(params.truncation_at(d));
        const Eigen::Vector3f ray =
            rotation * intrinsics.ray(x, static_cast<double>(y)).cast<float>();
        const Eigen::Vector3f near = origin + ray * (d - truncation);
        const Eigen::Vector3f far = origin + ray * (d + truncation);
        for_each_cell_on_segment(near.data(), far.data(), block_size,
                                 [&](int bx, int by, int bz) { pending.add(bx, by, bz); });
      }
    }
    std::vector<int>& local = found.local();
    for (const Eigen::Vector3i& block : pending.blocks()) {
      const int index = volume.allocate(block);
      if (index < 0) {
        pool_full.store(true, std::memory_order_relaxed);
        return;
      }
      if (volume.mark_visible(index, frame)) local.push_back(index);
    }
  });

  visible.indices.clear();
  for (const std::vector<int>& local : found)
    visible.indices.insert(visible.indices.end(), local.begin(), local.end());
  if (pool_full)
    throw Error("TSDF volume", "block pool",
                fmt::format("all {} blocks are in use; raise the block capacity (--blocks) or the "
                            "voxel size",
                            params.block_capacity));
}

namespace {

// A block is fused one x-row (kBlockSide voxels) at a time as vector lanes (vector_lanes.h; the
// build's baseline is plain x86-64, so the block kernel is compiled twice and picked once at
// run time). Where the CPU has AVX-512 (x86-64-v4), integrate_block_x86_64_v4() fuses two rows
// per register instead.
static_assert(kBlockSide == kLaneCount);
constexpr Floats kLanes{0, 1, 2, 3, 4, 5, 6, 7};
// Pool entries per 64-byte cache line, for prefetching the next block a line at a time.
constexpr int kFloatsPerLine = 64 / sizeof(float), kWeightsPerLine = 64 / sizeof(std::uint8_t);

// Fuses kRows consecutive rows (row r's voxel centres are first[r] + i * step_x in camera
// coordinates, i < kBlockSide; its voxels at r * kBlockSide in the arrays); fused_pixel[i] gets
// the pixel voxel i took its observation from, -1 where it took none. The rows' steps are
// interleaved: one row is a chain of dependent long-latency steps (a division, the depth
// gather, another division), which the CPU then overlaps with the other row's.
template <auto depth_at, int kRows>
[[gnu::always_inline]] inline void integrate_rows(const FrameConstants& k,
                                                  const float (&first)[kRows][3], float* sdf_m,
                                                  std::uint8_t* weight, std::int32_t* fused_pixel) {
  Floats z[kRows], u[kRows], v[kRows], d[kRows];
  Ints inside[kRows], pixel[kRows];
  for (int r = 0; r < kRows; ++r) {
    const Floats x = first[r][0] + kLanes * k.step_x[0], y = first[r][1] + kLanes * k.step_x[1];
    z[r] = first[r][2] + kLanes * k.step_x[2];
    const Floats inverse_z = 1.0f / z[r];
    u[r] = k.fx * x * inverse_z + k.cx;
    v[r] = k.fy * y * inverse_z + k.cy;
  }
  for (int r = 0; r < kRows; ++r) {
    // nearest_pixel() for every lane; outside lanes read pixel 0 and are masked off.
    inside[r] = z[r] > 0;
    nearest_pixels(u[r], v[r], k.width, k.height, inside[r], pixel[r]);
  }
  for (int r = 0; r < kRows; ++r) depth_at(k.depth, pixel[r], d[r]);
  for (int r = 0; r < kRows; ++r) {
    const int offset = r * kBlockSide;
    Floats sdf, w;
    std::memcpy(&sdf, sdf_m + offset, sizeof(sdf));
    load_bytes(weight + offset, w);
    Ints fused;
    fuse_voxel(d[r] - z[r], k.truncation_m + k.truncation_per_depth * d[r], k.max_weight,
               inside[r] & (d[r] >= k.depth_min) & (d[r] <= k.depth_max), sdf, w, fused);
    std::memcpy(sdf_m + offset, &sdf, sizeof(sdf));
    store_bytes(w, weight + offset);
    const Ints result = fused ? pixel[r] : -1;
    std::memcpy(fused_pixel + offset, &result, sizeof(result));
  }
}

// Fuses the block whose voxel (0, 0, 0) is at `origin` (camera coordinates); fused_pixel has
// one entry per voxel, as integrate_rows(). The blocks of a frame lie scattered in the pools,
// so the hardware prefetcher cannot guess the next one: each row fused here fetches the matching
// row of the next block (`next_sdf_m`, `next_weight`), which hid about half the cache misses.
template <auto depth_at>
[[gnu::always_inline]] inline void integrate_block(const FrameConstants& constants,
                                                   const float origin[3], float* sdf_m,
                                                   std::uint8_t* weight, std::int32_t* fused_pixel,
                                                   const float* next_sdf_m,
                                                   const std::uint8_t* next_weight) {
  // A local copy: through the reference, every store to the pools could alias the constants,
  // and each row reloaded all of them.
  const FrameConstants k = constants;
  for (int z = 0; z < kBlockSide; ++z) {
    // The first voxel of each of the slice's rows, one row per lane: computed row by row, these
    // scalar sums were a sixth of the block's instructions.
    Floats row_first[3];
    for (int axis = 0; axis < 3; ++axis)
      row_first[axis] = (origin[axis] + k.step_z[axis] * float(z)) + kLanes * k.step_y[axis];
    // Two rows at a time fill the vector units; four run out of vector registers.
    constexpr int kRows = 2;
    for (int y = 0; y < kBlockSide; y += kRows) {
      float first[kRows][3];
      for (int r = 0; r < kRows; ++r)
        for (int axis = 0; axis < 3; ++axis) first[r][axis] = row_first[axis][y + r];
      const int offset = (z * kBlockSide + y) * kBlockSide;
      if (offset % kFloatsPerLine == 0) __builtin_prefetch(next_sdf_m + offset, 1);
      if (offset % kWeightsPerLine == 0) __builtin_prefetch(next_weight + offset, 1);
      integrate_rows<depth_at, kRows>(k, first, sdf_m + offset, weight + offset,
                                      fused_pixel + offset);
    }
  }
}

using BlockKernel = void (*)(const FrameConstants&, const float[3], float*, std::uint8_t*,
                             std::int32_t*, const float*, const std::uint8_t*);

[[gnu::flatten]] void integrate_block_baseline(const FrameConstants& k, const float origin[3],
                                               float* sdf_m, std::uint8_t* weight,
                                               std::int32_t* fused_pixel, const float* next_sdf_m,
                                               const std::uint8_t* next_weight) {
  integrate_block<gather_lane_by_lane>(k, origin, sdf_m, weight, fused_pixel, next_sdf_m,
                                       next_weight);
}

#if defined(__x86_64__)
[[gnu::target("arch=x86-64-v3"), gnu::flatten]] void integrate_block_x86_64_v3(
    const FrameConstants& k, const float origin[3], float* sdf_m, std::uint8_t* weight,
    std::int32_t* fused_pixel, const float* next_sdf_m, const std::uint8_t* next_weight) {
  integrate_block<gather_avx2>(k, origin, sdf_m, weight, fused_pixel, next_sdf_m, next_weight);
}
#endif

#if defined(__x86_64__)
// The same block kernel with AVX-512 intrinsics, two rows per 16-lane register: rows y and y+1
// of a slice are 16 consecutive voxels in the pools. (GCC 12 compiles 16-lane vector-extension
// compares into scalar code, so this one is written with intrinsics.) Per lane it is
// integrate_rows()'s arithmetic in the same order.
[[gnu::target("arch=x86-64-v4")]] void integrate_block_x86_64_v4(
    const FrameConstants& constants, const float origin[3], float* sdf_m, std::uint8_t* weight,
    std::int32_t* fused_pixel, const float* next_sdf_m, const std::uint8_t* next_weight) {
  const FrameConstants k = constants;
  const __m512 lane_x = _mm512_setr_ps(0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7);
  const __m512 lane_y = _mm512_setr_ps(0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1);
  const __m512 one = _mm512_set1_ps(1.0f), half = _mm512_set1_ps(0.5f);
  const __m512 fx = _mm512_set1_ps(k.fx), fy = _mm512_set1_ps(k.fy);
  const __m512 cx = _mm512_set1_ps(k.cx), cy = _mm512_set1_ps(k.cy);
  const __m512 low = _mm512_set1_ps(-0.5f);
  const __m512 u_end = _mm512_set1_ps(float(k.width) - 0.5f);
  const __m512 v_end = _mm512_set1_ps(float(k.height) - 0.5f);
  const __m512 depth_min = _mm512_set1_ps(k.depth_min), depth_max = _mm512_set1_ps(k.depth_max);
  const __m512 truncation = _mm512_set1_ps(k.truncation_m);
  const __m512 truncation_per_depth = _mm512_set1_ps(k.truncation_per_depth);
  const __m512 max_weight = _mm512_set1_ps(k.max_weight);
  const __m512i width = _mm512_set1_epi32(k.width);
  const __m512i none = _mm512_set1_epi32(-1);
  __m512 step_x[3], step_y[3];
  for (int axis = 0; axis < 3; ++axis) {
    step_x[axis] = _mm512_set1_ps(k.step_x[axis]);
    step_y[axis] = _mm512_set1_ps(k.step_y[axis]);
  }
  for (int z = 0; z < kBlockSide; ++z) {
    __m512 slice[3];
    for (int axis = 0; axis < 3; ++axis)
      slice[axis] = _mm512_set1_ps(origin[axis] + k.step_z[axis] * float(z));
    for (int y = 0; y < kBlockSide; y += 2) {
      const int offset = (z * kBlockSide + y) * kBlockSide;
      __builtin_prefetch(next_sdf_m + offset, 1);
      if (offset % kWeightsPerLine == 0) __builtin_prefetch(next_weight + offset, 1);
      const __m512 row = _mm512_add_ps(lane_y, _mm512_set1_ps(float(y)));
      __m512 p[3];
      for (int axis = 0; axis < 3; ++axis)
        p[axis] =
            _mm512_fmadd_ps(lane_x, step_x[axis], _mm512_fmadd_ps(row, step_y[axis], slice[axis]));
      const __m512 inverse_z = _mm512_div_ps(one, p[2]);
      const __m512 u = _mm512_fmadd_ps(_mm512_mul_ps(fx, p[0]), inverse_z, cx);
      const __m512 v = _mm512_fmadd_ps(_mm512_mul_ps(fy, p[1]), inverse_z, cy);
      const __mmask16 inside =
          _mm512_cmp_ps_mask(p[2], _mm512_setzero_ps(), _CMP_GT_OQ) &
          _mm512_cmp_ps_mask(u, low, _CMP_GE_OQ) & _mm512_cmp_ps_mask(v, low, _CMP_GE_OQ) &
          _mm512_cmp_ps_mask(u, u_end, _CMP_LT_OQ) & _mm512_cmp_ps_mask(v, v_end, _CMP_LT_OQ);
      const __m512i column = _mm512_maskz_cvttps_epi32(inside, _mm512_add_ps(u, half));
      const __m512i pixel_row = _mm512_maskz_cvttps_epi32(inside, _mm512_add_ps(v, half));
      const __m512i pixel = _mm512_add_epi32(_mm512_mullo_epi32(pixel_row, width), column);
      const __m512 d =
          _mm512_mask_i32gather_ps(_mm512_setzero_ps(), inside, pixel, k.depth, sizeof(float));
      __m512 sdf = _mm512_loadu_ps(sdf_m + offset);
      __m512 w = _mm512_maskz_cvtepi32_ps(
          0xffff, _mm512_maskz_cvtepu8_epi32(
                      0xffff, _mm_loadu_si128(reinterpret_cast<const __m128i*>(weight + offset))));
      const __m512 measured = _mm512_sub_ps(d, p[2]);
      const __m512 band = _mm512_fmadd_ps(truncation_per_depth, d, truncation);
      // fuse_voxel(): valid, not more than the band behind the surface, clamped in front.
      const __mmask16 fused =
          inside & _mm512_cmp_ps_mask(d, depth_min, _CMP_GE_OQ) &
          _mm512_cmp_ps_mask(d, depth_max, _CMP_LE_OQ) &
          _mm512_cmp_ps_mask(measured, _mm512_sub_ps(_mm512_setzero_ps(), band), _CMP_GE_OQ);
      // vminps(a, b) is a < b ? a : b, fuse_voxel()'s clamps exactly; lanes not fused keep
      // their voxel.
      const __m512 observation = _mm512_maskz_min_ps(fused, measured, band);
      const __m512 total = _mm512_add_ps(w, one);
      sdf = _mm512_mask_div_ps(sdf, fused, _mm512_fmadd_ps(sdf, w, observation), total);
      w = _mm512_mask_min_ps(w, fused, total, max_weight);
      _mm512_storeu_ps(sdf_m + offset, sdf);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(weight + offset),
                       _mm512_maskz_cvtepi32_epi8(0xffff, _mm512_maskz_cvttps_epi32(0xffff, w)));
      _mm512_storeu_si512(fused_pixel + offset, _mm512_mask_blend_epi32(fused, none, pixel));
    }
  }
}
#endif

BlockKernel block_kernel() {
#if defined(__x86_64__)
  if (cpu_has_x86_64_v4()) return integrate_block_x86_64_v4;
  if (cpu_has_x86_64_v3()) return integrate_block_x86_64_v3;
#endif
  return integrate_block_baseline;
}

// The running mean of the colours each voxel of a block was fused with (fused_pixel: the
// voxel's pixel, or -1 where it was not fused; weight_before: its weight before this frame).
// (restrict: the frame's planes and the block's colours never overlap.)
void fuse_block_colours(const std::int32_t* fused_pixel, const float* weight_before,
                        const std::array<const float*, 3>& frame,
                        const std::array<float*, 3>& block) {
  const float* __restrict red_in = frame[0];
  const float* __restrict green_in = frame[1];
  const float* __restrict blue_in = frame[2];
  float* __restrict red = block[0];
  float* __restrict green = block[1];
  float* __restrict blue = block[2];
  for (int v = 0; v < kVoxelsPerBlock; ++v) {
    const int pixel = fused_pixel[v];
    if (pixel < 0) continue;
    red[v] = fuse_colour(red[v], weight_before[v], red_in[pixel]);
    green[v] = fuse_colour(green[v], weight_before[v], green_in[pixel]);
    blue[v] = fuse_colour(blue[v], weight_before[v], blue_in[pixel]);
  }
}

}  // namespace

FrameIntegration::FrameIntegration(const TsdfVolume& volume, const VisibleBlocks& visible,
                                   const ImageF& depth_m, const ImageF& colour,
                                   const Intrinsics& intrinsics, const Pose& camera_to_world)
    : volume_(volume) {
  require_same_size(depth_m, colour, intrinsics);
  if (!colour.empty() && !volume.has_colour())
    throw Error("TSDF volume", "colour", "keeps no colour (VolumeParams::colour is off)");
  const VolumeParams& params = volume.params();
  const Pose world_to_camera = camera_to_world.inverse();
  rotation_ = world_to_camera.linear().cast<float>();
  translation_ = world_to_camera.translation().cast<float>();
  const float voxel = static_cast<float>(params.voxel_size_m);
  const Eigen::Vector3f step_x = rotation_.col(0) * voxel;
  const Eigen::Vector3f step_y = rotation_.col(1) * voxel;
  const Eigen::Vector3f step_z = rotation_.col(2) * voxel;
  constants_ = FrameConstants{static_cast<float>(intrinsics.fx),
                              static_cast<float>(intrinsics.fy),
                              static_cast<float>(intrinsics.cx),
                              static_cast<float>(intrinsics.cy),
                              depth_m.width(),
                              depth_m.height(),
                              static_cast<float>(params.depth_min_m),
                              static_cast<float>(params.depth_max_m),
                              static_cast<float>(params.truncation_m),
                              static_cast<float>(params.truncation_per_depth),
                              params.max_weight,
                              depth_m.plane(0),
                              {step_x.x(), step_x.y(), step_x.z()},
                              {step_y.x(), step_y.y(), step_y.z()},
                              {step_z.x(), step_z.y(), step_z.z()}};
  half_block_ = (step_x + step_y + step_z) * (0.5f * kBlockSide);
  far_depth_ = float(params.far_field_depth_m(intrinsics.fx));
  far_every_ = params.far_fusion_every;
  frame_ = std::max(visible.frame, 0);
}

void integrate_blocks(TsdfVolume& volume, const VisibleBlocks& visible, const ImageF& depth_m,
                      const ImageF& colour, const Intrinsics& intrinsics,
                      const Pose& camera_to_world) {
  const FrameIntegration frame(volume, visible, depth_m, colour, intrinsics, camera_to_world);
  const bool with_colour = !colour.empty();
  const float* red_in = with_colour ? colour.plane(0) : nullptr;
  const float* green_in = with_colour ? colour.plane(1) : nullptr;
  const float* blue_in = with_colour ? colour.plane(2) : nullptr;

  static const BlockKernel fuse_block = block_kernel();
  const std::size_t blocks = visible.indices.size();
  parallel_for(blocks, [&](std::size_t i) {
    const int block = visible.indices[i];
    const int next_block = visible.indices[i + 1 < blocks ? i + 1 : i];
    const Eigen::Vector3f origin = frame.block_origin(block);
    if (!frame.fused_now(block, origin)) return;
    volume.count_fusion(block);
    float* sdf = volume.sdf_m(block);
    std::uint8_t* weight = volume.weight(block);
    // The weights before this observation, for the colour average.
    std::array<float, kVoxelsPerBlock> weight_before;
    if (with_colour) std::copy_n(weight, kVoxelsPerBlock, weight_before.begin());
    std::array<std::int32_t, kVoxelsPerBlock> fused_pixel;
    fuse_block(frame.constants(), origin.data(), sdf, weight, fused_pixel.data(),
               volume.sdf_m(next_block), volume.weight(next_block));
    if (!with_colour) return;
    fuse_block_colours(fused_pixel.data(), weight_before.data(), {red_in, green_in, blue_in},
                       {volume.red(block), volume.green(block), volume.blue(block)});
  });
}

void integrate(TsdfVolume& volume, const ImageF& depth_m, const ImageF& colour,
               const Intrinsics& intrinsics, const Pose& camera_to_world, VisibleBlocks& visible) {
  allocate_blocks(volume, depth_m, intrinsics, camera_to_world, visible);
  integrate_blocks(volume, visible, depth_m, colour, intrinsics, camera_to_world);
}

}  // namespace glint::fusion
