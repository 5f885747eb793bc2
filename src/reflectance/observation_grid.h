#pragma once
// ObservationGrid: the coarse voxel hash that collects reflectance observations (paper 1 §3.4).
// It is separate from the geometry's TSDF: its voxels are 2 cm or 1 cm (the TSDF's 5 mm), so a
// block of the TSDF's spatial extent holds 2^3 or 4^3 of them, and it has its own fixed pools.
//
// Per voxel it keeps:
//  - a surface point and normal, taken from the fused TSDF: the voxel centre moved onto the zero
//    level set along the SDF gradient (two Newton steps), refreshed every few frames while the
//    geometry converges; voxels the surface does not pass through have none, and are retried
//    ever less often. The normal is the plane through the surface points of the voxel and its
//    neighbours (see normal_from_neighbours); the TSDF gradient only where too few neighbours
//    have one;
//  - at most `observations_per_voxel` (m = 30) observations: linear radiance (pixel / exposure)
//    and the unit voxel-to-camera direction, with the most-similar-pair replacement of
//    reflectance/observation.h;
//  - its segment id and a confidence (reflectance/segment_map.h) and its refined diffuse albedo
//    (reflectance/albedo_refinement.h).
//
// collect() runs once per frame: every allocation_stride_px-th depth pixel allocates the voxel
// it back-projects into; each voxel of the frame's blocks is then projected into the depth
// image and observed when it is in front of the camera, faces it, and its depth agrees with the
// measured one (the visibility / occlusion test). Pools are allocated once; their memory is
// committed as voxels are used.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "core/pool_memory.h"
#include "fusion/block_index_cache.h"
#include "fusion/tsdf_sampler.h"
#include "fusion/tsdf_volume.h"
#include "fusion/voxel_block_hash.h"
#include "reflectance/observation.h"

namespace glint::reflectance {

struct ObservationGridParams {
  double voxel_size_m = 0.02;  // paper 1 §4.1: 2 cm (low) or 1 cm (high resolution)
  // A block spans the geometry block's extent (8 TSDF voxels): (block_size_m / voxel_size_m)^3
  // voxels, 2^3 or 4^3 with the defaults.
  double block_size_m = 0.04;
  int observations_per_voxel = 30;  // m
  // Pool size; exhaustion is a glint::Error. 0: 2^20 voxels at 2 cm and above, and
  // 2 (0.02 / voxel_size_m)^2 times that below (a surface holds (0.02 / v)^2 times as many
  // voxels, and finer grids leave more of each block empty). About 75 bytes per voxel and
  // 630 bytes of observation slots per voxel that has been observed, committed as they are used.
  std::size_t voxel_capacity = 0;
  int allocation_stride_px = 2;       // every n-th pixel of every n-th row allocates
  double depth_tolerance_m = 0.01;    // |measured - voxel depth| allowed, plus ...
  double depth_tolerance_sigmas = 3;  // ... this many Kinect sigma(z) (render/sensor.h)
  double min_view_cosine = 0.1;       // normal . direction of an accepted observation
  // An observation seen within this angle of the voxel's newest stored one is not stored (the
  // voxel still counts as seen in the frame). Along a smooth camera path successive frames see
  // a voxel from nearly the same direction (office: about 0.7 degrees per frame at 4.5 m), and
  // such a pair adds nothing to the hemisphere coverage that m = 30 observations approximate:
  // once the voxel is full it is the first pair the replacement rule merges. 0 stores every
  // observation, as the paper does and as the HemiCNN's training data were collected
  // (hemi_extraction.h); the reflectance pipeline uses 1 degree (ReflectanceParams).
  double min_observation_spacing_deg = 0;
  // An observation is stored however close to the newest stored one once that is this many
  // frames old (0: never). A slow hand-held camera would otherwise leave most voxels short of
  // the specular stage's SpecularParams::min_observations (5) and their segments without a
  // material; a camera sweeping a voxel by the spacing within this many frames is unaffected.
  int spacing_max_frames = 0;
  int geometry_refresh_frames = 8;  // surface point / normal recomputed this often
  // The normal as the least-squares plane through the surface points of the voxel and its (up
  // to 26) neighbours, instead of the TSDF gradient at the point. The gradient of a TSDF fused
  // from millimetre-quantised depth tilts by 1-3 degrees on a flat face, which puts a sharp
  // highlight's predicted lobe (alpha 0.05 is 3 degrees wide) beside the observed one; the
  // zero crossings are far steadier than the slopes between them.
  bool normal_from_neighbours = true;
  // A voxel without surface is retried after geometry_refresh_frames, then twice, four times ...
  // as long, doubling at most this many times.
  int surface_retry_doublings = 3;
  // A surface point that a refresh moved by less than this fraction of the voxel size has
  // settled: its next refresh waits twice as long (at most settled_refresh_doublings times).
  // The plane normal through points that move by 0.005 voxel tilts by at most ~0.3 degrees; on
  // bunnies 60-75 % of the refreshes after frame 100 move the point less than that.
  double settled_shift = 0.005;
  int settled_refresh_doublings = 3;
};

// One voxel seen in the current frame: its pool index and the pixel it projects to.
struct VisibleVoxel {
  int voxel = 0;
  int pixel = 0;  // y * width + x
};

class ObservationGrid {
 public:
  explicit ObservationGrid(const ObservationGridParams& params = {});

  const ObservationGridParams& params() const { return params_; }
  int voxels_per_block_side() const { return side_; }
  std::size_t voxel_count() const { return hash_.size() * voxels_per_block_; }
  // The pools' size: every pool index is below it (per-voxel data kept elsewhere is sized so).
  std::size_t voxel_pool_size() const { return hash_.capacity() * voxels_per_block_; }
  std::size_t block_count() const { return hash_.size(); }

  // One frame: depth in metres (0 = none), linear RGB colour of the same size, the frame's pose,
  // `exposure` (radiance = colour / exposure) and the fused geometry. Returns the voxels observed
  // in this frame (each once). Throws glint::Error when the pool is exhausted or sizes differ.
  const std::vector<VisibleVoxel>& collect(const ImageF& depth_m, const ImageF& colour,
                                           const Intrinsics& intrinsics,
                                           const Pose& camera_to_world, float exposure,
                                           const fusion::TsdfVolume& geometry, int frame);

  // The latest collect()'s result.
  const std::vector<VisibleVoxel>& visible() const { return visible_; }

  // Per-voxel data, by pool index (< voxel_count()).
  bool has_surface(int v) const { return has_surface_[v]; }
  const Eigen::Vector3f& position(int v) const { return position_[v]; }
  const Eigen::Vector3f& normal(int v) const { return normal_[v]; }
  int observation_count(int v) const { return observation_count_[v]; }
  const Observation* observations(int v) const { return observations_.get() + first_slot(v); }
  // The first of voxel v's observation slots (0 while it has none: nothing reads them then),
  // below voxel_pool_size() * observations_per_voxel: per-slot data kept elsewhere is indexed
  // by it.
  std::size_t first_slot(int v) const {
    return observation_set_[v] == 0
               ? 0
               : std::size_t(observation_set_[v] - 1) * params_.observations_per_voxel;
  }
  // Asks for voxel v's own state (observation count and slots, surface point, normal, segment)
  // ahead of use: a frame's voxels lie scattered in the pools.
  void prefetch_voxel(int v) const;
  // Asks for voxel v's stored observations (about 1 KB, usually a cache miss) ahead of use, with
  // `for_insertion` also their nearest-observation entries. Reads the voxel's count and slots,
  // so prefetch_voxel(v) should come some iterations earlier.
  void prefetch_observations(int v, bool for_insertion) const;
  std::int32_t& segment(int v) { return segment_[v]; }
  std::int32_t segment(int v) const { return segment_[v]; }
  std::int16_t& segment_confidence(int v) { return segment_confidence_[v]; }
  // Asks for voxel v's segment id and confidence ahead of use (the voxels of a frame lie
  // scattered in the pools).
  void prefetch_segment(int v) const {
    __builtin_prefetch(&segment_[v], 1);
    __builtin_prefetch(&segment_confidence_[v], 1);
  }
  Eigen::Vector3f& refined_kd(int v) { return refined_kd_[v]; }
  const Eigen::Vector3f& refined_kd(int v) const { return refined_kd_[v]; }
  bool& has_refined_kd(int v) { return has_refined_kd_[v]; }
  bool has_refined_kd(int v) const { return has_refined_kd_[v]; }
  // Whether the refined albedo was solved under light steep enough to trust it
  // (RefinedAlbedo::light_cosine, ReflectanceParams::albedo_min_light_cosine).
  bool& refined_kd_reliable(int v) { return refined_kd_reliable_[v]; }
  bool refined_kd_reliable(int v) const { return refined_kd_reliable_[v]; }
  // The tangent of that light's effective incidence angle (RefinedAlbedo::light_tangent; 0 until
  // set), which weighs the voxel among its neighbours (refined_albedo_weight).
  float& refined_kd_light_tangent(int v) { return refined_kd_light_tangent_[v]; }
  float refined_kd_light_tangent(int v) const { return refined_kd_light_tangent_[v]; }
  // The share of the reaching lights' direct light that the voxel's observations lack, in
  // [0, 1]: 0 where eq. (7) explains them, else 1 - (its refined albedo over its segment's, by
  // their largest channels) where that albedo is too dark to trust
  // (ReflectanceParams::albedo_max_ratio), a shadow the fused geometry cannot cast. Re-renderings
  // dim the direct light there by it.
  float& light_shortfall(int v) { return light_shortfall_[v]; }
  float light_shortfall(int v) const { return light_shortfall_[v]; }

  // Look-ups of many nearby voxels (a rendering's pixels, a mesh's vertices) may keep the
  // blocks they found in a cache of their own (one per thread), which spares most hash look-ups.
  using BlockCache = fusion::BlockIndexCache<4>;
  static constexpr int kMaxFindVoxelsSide = 4;
  // Pool index of the voxel containing world point p, or -1.
  int find(const Eigen::Vector3f& p, BlockCache* cache = nullptr) const;
  // Pool index of the voxel at integer grid coordinates, or -1.
  int find_voxel(const Eigen::Vector3i& voxel, BlockCache* cache = nullptr) const;
  // find_voxel() of the n^3 voxels from grid coordinates `first` on (x fastest, then y, z) into
  // voxels[0, n^3), with one block look-up per block they touch; n in 1..kMaxFindVoxelsSide.
  void find_voxels(const Eigen::Vector3i& first, int n, int* voxels,
                   BlockCache* cache = nullptr) const;
  // Integer grid coordinates of pool index v.
  Eigen::Vector3i voxel_coordinates(int v) const;
  // World centre of the voxel at integer grid coordinates.
  Eigen::Vector3f voxel_centre(const Eigen::Vector3i& voxel) const {
    return (voxel.cast<float>() + Eigen::Vector3f::Constant(0.5f)) * float(params_.voxel_size_m);
  }

 private:
  // The pool index of a block of this grid, through `cache` when there is one.
  int find_block(const Eigen::Vector3i& block, BlockCache* cache) const {
    if (!cache) return hash_.find(block);
    return (*cache)(block, [&](const Eigen::Vector3i& b) { return hash_.find(b); });
  }

  // Coordinates within its block of the voxel with in-block index `local`.
  Eigen::Vector3i local_coordinates(int local) const {
    return {local % side_, (local / side_) % side_, local / (side_ * side_)};
  }
  int voxel_index(int block, const Eigen::Vector3i& local) const {
    return block * voxels_per_block_ + (local.z() * side_ + local.y()) * side_ + local.x();
  }
  void allocate(const ImageF& depth_m, const Intrinsics& intrinsics, const Pose& camera_to_world,
                int frame);
  void refresh_surface(int v, const Eigen::Vector3f& centre, int frame,
                       fusion::TsdfSampler& sampler);
  // The frame after `frame` at which a voxel is refreshed again: its surface search has failed
  // `misses` times in a row, or (misses 0) found a point that stayed put `settled` times in a row.
  int next_refresh(int frame, int misses, int settled) const {
    return frame + (params_.geometry_refresh_frames << (misses > 0 ? misses - 1 : settled));
  }
  // Pool indices (-1: none) of the 3^3 blocks around a block, neighbour_offset(i) from it.
  using NeighbourBlocks = std::array<int, 27>;
  static Eigen::Vector3i neighbour_offset(int i) { return {i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1}; }
  static constexpr int kOwnBlock = 13;  // neighbour_offset(13) is zero
  // Replaces the gradient normals of the voxels of frame_blocks_[slot] refreshed in `frame` by
  // the plane through their neighbours' surface points (ObservationGridParams); `around` are
  // the blocks around it (find_neighbours). Before it, in this order, some blocks ahead:
  // prefetch_neighbour_slots(), find_neighbours() and prefetch_refit_state().
  void fit_normals_to_neighbours(std::size_t slot, int frame, const NeighbourBlocks& around);
  void prefetch_neighbour_slots(std::size_t slot) const;
  void find_neighbours(std::size_t slot, NeighbourBlocks& around) const;
  void prefetch_refit_state(const NeighbourBlocks& around) const;
  // Prefetch the per-voxel state collect() reads first for the voxels of `block`: their refresh
  // frames and surface flags, then (a block later, reading the flags) the rest.
  void prefetch_surface_flags(int block) const;
  void prefetch_voxel_state(int block) const;
  // The TSDF (geometry) blocks and, per block, the cache lines of its distances that the first
  // reads of an observation block's due surface refreshes touch (the box around their
  // stencils; fusion::TsdfVolume::distance_lines).
  struct GeometryReads {
    static constexpr int kCapacity = 27;  // 3^3; more are not prefetched (read when needed)
    int count = 0;
    std::array<Eigen::Vector3i, kCapacity> blocks;
    std::array<std::uint32_t, kCapacity> lines;
    void add(const Eigen::Vector3i& block, std::uint32_t block_lines);
  };
  // Those of the refreshes due in `frame` for the voxels of `block`; `inverse_geometry_voxel` is
  // 1 / the TSDF's voxel size.
  void geometry_reads_due(int block, int frame, float inverse_geometry_voxel,
                          GeometryReads& reads) const;

  ObservationGridParams params_;
  int side_ = 2;
  int voxels_per_block_ = 8;
  fusion::VoxelBlockHash hash_;
  std::unique_ptr<std::atomic<int>[]> block_last_frame_;
  std::vector<int> frame_blocks_;
  // allocate()'s scratch: per chunk of depth rows, its blocks and their pool indices.
  std::vector<std::vector<std::pair<Eigen::Vector3i, int>>> chunk_blocks_;
  // Per frame block: whether a refresh in this frame found a surface in one of its voxels (the
  // blocks whose normals are refitted), and the slots of those blocks.
  std::vector<std::uint8_t> block_refreshed_;
  std::vector<std::size_t> refit_blocks_;

  // Structure-of-arrays voxel pools (zero-initialised, committed on first touch).
  // A voxel's m observation slots are taken from observations_ / nearest_ at its first
  // observation, in the order voxels are first seen: most voxels of a block never see the
  // surface, and slots reserved for every voxel had the kernel zeroing ~1 KB for each of them.
  PoolArray<Observation> observations_;
  PoolArray<float> nearest_similarity_;  // NearestObservations, parallel to observations_
  PoolArray<std::uint8_t> nearest_slot_;
  PoolArray<std::int32_t> observation_set_;  // 1 + its set of slots, 0 = none yet
  std::atomic<std::int32_t> observation_sets_used_{0};
  PoolArray<std::uint8_t> observation_count_;
  struct NewestObservation {
    Eigen::Vector3f direction;
    std::int32_t frame;
  };
  PoolArray<NewestObservation> newest_;  // the latest stored observation's
  PoolArray<Eigen::Vector3f> position_, normal_, refined_kd_;
  PoolArray<int> next_refresh_frame_;        // frame of the next surface refresh
  PoolArray<std::uint8_t> surface_misses_;   // refreshes in a row that found no surface
  PoolArray<std::uint8_t> surface_settled_;  // refreshes in a row that barely moved the point
  PoolArray<bool> has_surface_;
  PoolArray<std::int32_t> segment_;
  PoolArray<std::int16_t> segment_confidence_;
  PoolArray<bool> has_refined_kd_, refined_kd_reliable_;
  PoolArray<float> refined_kd_light_tangent_, light_shortfall_;

  std::vector<VisibleVoxel> visible_;
  // collect()'s scratch: per frame block, voxels_per_block_ entries of which the first
  // visible_in_block_[slot] are its observed voxels.
  std::vector<VisibleVoxel> visible_by_block_;
  std::vector<int> visible_in_block_;
};

}  // namespace glint::reflectance
