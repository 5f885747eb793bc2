#include "reflectance/observation_grid.h"

#include <tbb/enumerable_thread_specific.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "core/error.h"
#include "core/parallel.h"
#include "fusion/tsdf_kernels.h"
#include "fusion/tsdf_sampler.h"

namespace glint::reflectance {
namespace {

// A per-voxel (or per-observation) pool; its errors name the grid.
template <class T>
PoolArray<T> voxel_pool(std::size_t count) {
  return make_pool<T>(count, "observation grid");
}

// The normal of the least-squares plane through `count` points, on `reference`'s side; nullopt for
// fewer than five points or points along a line (a thin strip of surface fixes no plane).
std::optional<Eigen::Vector3f> fit_plane(const Eigen::Vector3f* points, int count,
                                         const Eigen::Vector3f& reference) {
  constexpr int kMinPoints = 5;
  if (count < kMinPoints) return std::nullopt;
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  Eigen::Matrix3f products = Eigen::Matrix3f::Zero();
  for (int i = 0; i < count; ++i) {
    sum += points[i];
    products += points[i] * points[i].transpose();
  }
  const Eigen::Vector3f mean = sum / float(count);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver;
  solver.computeDirect(products / float(count) - mean * mean.transpose());  // closed form
  const Eigen::Vector3f spread = solver.eigenvalues();                      // ascending
  if (!(spread[0] <= 0.1f * spread[1])) return std::nullopt;
  Eigen::Vector3f normal = solver.eigenvectors().col(0).normalized();
  if (normal.dot(reference) < 0) normal = -normal;
  return normal;
}

// Prefetches the lines holding elements i of `block_first` whose bit i is set in `elements`.
template <class T>
void prefetch_selected(const T* block_first, std::uint64_t elements) {
  std::uintptr_t last = ~std::uintptr_t(0);
  for (; elements != 0; elements &= elements - 1) {
    const auto* element = reinterpret_cast<const char*>(block_first + std::countr_zero(elements));
    const std::uintptr_t line = reinterpret_cast<std::uintptr_t>(element + sizeof(T) - 1) / 64;
    if (line == last) continue;
    __builtin_prefetch(element);
    __builtin_prefetch(element + sizeof(T) - 1);
    last = line;
  }
}

// Bit i set where flags[i] (bytes of 0 or 1), for 8 flags.
std::uint64_t flag_bits(const bool* flags) {
  std::uint64_t word;
  std::memcpy(&word, flags, sizeof(word));
  return (word * 0x0102040810204080ull) >> 56;
}

Eigen::Vector3i floor_div(const Eigen::Vector3i& v, int side) {
  return {v.x() >= 0 ? v.x() / side : -((-v.x() + side - 1) / side),
          v.y() >= 0 ? v.y() / side : -((-v.y() + side - 1) / side),
          v.z() >= 0 ? v.z() / side : -((-v.z() + side - 1) / side)};
}

int block_side(const ObservationGridParams& params) {
  if (!(params.voxel_size_m > 0) || !(params.block_size_m >= params.voxel_size_m))
    throw Error("observation grid", "voxel_size_m",
                "must be positive and at most the block size " +
                    std::to_string(params.block_size_m) + " m");
  const int side = static_cast<int>(std::lround(params.block_size_m / params.voxel_size_m));
  if (std::fabs(side * params.voxel_size_m - params.block_size_m) > 1e-6)
    throw Error("observation grid", "voxel_size_m",
                "must divide the block size " + std::to_string(params.block_size_m) + " m");
  return side;
}

std::size_t voxel_capacity(const ObservationGridParams& params) {
  if (params.voxel_capacity > 0) return params.voxel_capacity;
  const double finer = 0.02 / params.voxel_size_m;
  return std::size_t(double(1u << 20) * std::max(1.0, 2.0 * finer * finer));
}

}  // namespace

void ObservationGrid::prefetch_voxel(int v) const {
  __builtin_prefetch(&observation_count_[v]);
  __builtin_prefetch(&observation_set_[v]);
  __builtin_prefetch(&position_[v]);
  __builtin_prefetch(&normal_[v]);
  __builtin_prefetch(&segment_[v]);
}

void ObservationGrid::prefetch_observations(int v, bool for_insertion) const {
  const std::size_t first = first_slot(v);
  prefetch_lines(observations_.get() + first, observation_count_[v] * sizeof(Observation));
  if (for_insertion) {
    prefetch_lines(nearest_similarity_.get() + first, observation_count_[v] * sizeof(float));
    prefetch_lines(nearest_slot_.get() + first, observation_count_[v] * sizeof(std::uint8_t));
  }
}

void ObservationGrid::prefetch_surface_flags(int block) const {
  const std::size_t first = std::size_t(block) * voxels_per_block_;
  prefetch_lines(next_refresh_frame_.get() + first, voxels_per_block_ * sizeof(int));
  prefetch_lines(has_surface_.get() + first, voxels_per_block_ * sizeof(bool));
}

void ObservationGrid::prefetch_voxel_state(int block) const {
  const std::size_t first = std::size_t(block) * voxels_per_block_;
  const std::size_t voxels = voxels_per_block_;
  prefetch_lines(observation_count_.get() + first, voxels * sizeof(std::uint8_t));
  prefetch_lines(observation_set_.get() + first, voxels * sizeof(std::int32_t));
  // At 1 cm about 8 of a block's 64 voxels have a surface, and only they are projected and
  // observed: their points, normals and newest directions are asked for instead of the block's
  // 40 lines of them. The surface flags were asked for a block earlier (prefetch_surface_flags).
  if (voxels_per_block_ == 64) {
    std::uint64_t surface = 0;
    for (int word = 0; word < 8; ++word)
      surface |= flag_bits(has_surface_.get() + first + 8 * word) << (8 * word);
    prefetch_selected(position_.get() + first, surface);
    prefetch_selected(normal_.get() + first, surface);
    prefetch_selected(newest_.get() + first, surface);
    return;
  }
  prefetch_lines(position_.get() + first, voxels * sizeof(Eigen::Vector3f));
  prefetch_lines(normal_.get() + first, voxels * sizeof(Eigen::Vector3f));
  prefetch_lines(newest_.get() + first, voxels * sizeof(NewestObservation));
}

void ObservationGrid::GeometryReads::add(const Eigen::Vector3i& block, std::uint32_t block_lines) {
  if (count == kCapacity) return;
  blocks[std::size_t(count)] = block;
  lines[std::size_t(count++)] = block_lines;
}

void ObservationGrid::geometry_reads_due(int block, int frame, float inverse_geometry_voxel,
                                         GeometryReads& reads) const {
  // A refresh first reads the 4^3 TSDF voxels from floor(p) - 1 on around its start p, the
  // surface point or (without one) the voxel centre (TsdfSampler::trilinear_with_gradient). Only
  // the lines of the box that holds those stencils are asked for: the whole blocks the stencils
  // might reach are 8 x 32 lines where a refresh or two reads a few dozen, and so many
  // prefetches stall on the full line-fill buffers. A second Newton step from a voxel centre
  // reads around its landing point, unprefetched.
  reads.count = 0;
  const int first = block * voxels_per_block_;
  const Eigen::Vector3i first_voxel = hash_.block(block) * side_;
  // The box of TSDF voxels that holds every due voxel's stencil.
  Eigen::Vector3i low = Eigen::Vector3i::Constant(std::numeric_limits<int>::max());
  Eigen::Vector3i high = Eigen::Vector3i::Constant(std::numeric_limits<int>::min());
  for (int local = 0; local < voxels_per_block_; ++local) {
    const int v = first + local;
    if (frame < next_refresh_frame_[v]) continue;
    const Eigen::Vector3f start =
        (has_surface_[v] ? position_[v] : voxel_centre(first_voxel + local_coordinates(local))) *
        inverse_geometry_voxel;
    const Eigen::Vector3i cell(int(std::floor(start.x())), int(std::floor(start.y())),
                               int(std::floor(start.z())));
    low = low.cwiseMin(cell - Eigen::Vector3i::Ones());
    high = high.cwiseMax(cell + Eigen::Vector3i::Constant(2));
  }
  if (low.x() > high.x()) return;  // none due
  using fusion::kBlockShift;
  const auto in_block = [](int value, int b) {
    return std::clamp(value - (b << kBlockShift), 0, fusion::kBlockSide - 1);
  };
  for (int bz = low.z() >> kBlockShift; bz <= high.z() >> kBlockShift; ++bz)
    for (int by = low.y() >> kBlockShift; by <= high.y() >> kBlockShift; ++by)
      for (int bx = low.x() >> kBlockShift; bx <= high.x() >> kBlockShift; ++bx)
        reads.add({bx, by, bz}, fusion::TsdfVolume::distance_lines(
                                    in_block(low.y(), by), in_block(high.y(), by),
                                    in_block(low.z(), bz), in_block(high.z(), bz)));
}

ObservationGrid::ObservationGrid(const ObservationGridParams& params)
    : params_(params),
      side_(block_side(params)),
      voxels_per_block_(side_ * side_ * side_),
      hash_(std::max<std::size_t>(1, voxel_capacity(params) / std::size_t(side_ * side_ * side_))) {
  if (params.observations_per_voxel < 1 || params.observations_per_voxel > kMaxObservationsPerVoxel)
    throw Error("observation grid", "observations_per_voxel",
                "must be in 1.." + std::to_string(kMaxObservationsPerVoxel));
  if (params.allocation_stride_px < 1)
    throw Error("observation grid", "allocation_stride_px", "must be >= 1");
  if (params.geometry_refresh_frames < 1)
    throw Error("observation grid", "geometry_refresh_frames", "must be >= 1");
  if (params.surface_retry_doublings < 0 || params.surface_retry_doublings > 8)
    throw Error("observation grid", "surface_retry_doublings", "must be in 0..8");
  if (params.settled_refresh_doublings < 0 || params.settled_refresh_doublings > 8)
    throw Error("observation grid", "settled_refresh_doublings", "must be in 0..8");
  if (!(params.settled_shift >= 0))
    throw Error("observation grid", "settled_shift", "must be >= 0");
  if (!(params.min_observation_spacing_deg >= 0 && params.min_observation_spacing_deg < 90))
    throw Error("observation grid", "min_observation_spacing_deg", "must be in [0, 90)");
  if (params.spacing_max_frames < 0)
    throw Error("observation grid", "spacing_max_frames", "must be >= 0");
  const std::size_t voxels = hash_.capacity() * voxels_per_block_;
  observations_ = voxel_pool<Observation>(voxels * params.observations_per_voxel);
  nearest_similarity_ = voxel_pool<float>(voxels * params.observations_per_voxel);
  nearest_slot_ = voxel_pool<std::uint8_t>(voxels * params.observations_per_voxel);
  observation_set_ = voxel_pool<std::int32_t>(voxels);
  observation_count_ = voxel_pool<std::uint8_t>(voxels);
  newest_ = voxel_pool<NewestObservation>(voxels);
  position_ = voxel_pool<Eigen::Vector3f>(voxels);
  normal_ = voxel_pool<Eigen::Vector3f>(voxels);
  refined_kd_ = voxel_pool<Eigen::Vector3f>(voxels);
  next_refresh_frame_ = voxel_pool<int>(voxels);
  surface_misses_ = voxel_pool<std::uint8_t>(voxels);
  surface_settled_ = voxel_pool<std::uint8_t>(voxels);
  has_surface_ = voxel_pool<bool>(voxels);
  segment_ = voxel_pool<std::int32_t>(voxels);
  segment_confidence_ = voxel_pool<std::int16_t>(voxels);
  has_refined_kd_ = voxel_pool<bool>(voxels);
  refined_kd_reliable_ = voxel_pool<bool>(voxels);
  refined_kd_light_tangent_ = voxel_pool<float>(voxels);
  light_shortfall_ = voxel_pool<float>(voxels);
  block_last_frame_ = std::make_unique<std::atomic<int>[]>(hash_.capacity());
  for (std::size_t i = 0; i < hash_.capacity(); ++i) block_last_frame_[i] = -1;
}

int ObservationGrid::find_voxel(const Eigen::Vector3i& voxel, BlockCache* cache) const {
  const Eigen::Vector3i block = floor_div(voxel, side_);
  const int index = find_block(block, cache);
  if (index < 0) return -1;
  return voxel_index(index, voxel - block * side_);
}

void ObservationGrid::find_voxels(const Eigen::Vector3i& first, int n, int* voxels,
                                  BlockCache* cache) const {
  if (n < 1 || n > kMaxFindVoxelsSide)
    throw Error("observation grid", "find_voxels",
                "n must be in 1.." + std::to_string(kMaxFindVoxelsSide));
  // Per axis and position: the block (counted from first's block) and the voxel's offset in it.
  // The blocks are looked up once each, then every voxel's index is a sum without a branch
  // (loops over each block's part of the cube mispredicted their short, varying trip counts).
  const Eigen::Vector3i first_block = floor_div(first, side_);
  std::array<std::array<int, kMaxFindVoxelsSide>, 3> block_of, offset;
  Eigen::Vector3i blocks;
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < n; ++i) {
      const int local = first[axis] - first_block[axis] * side_ + i;
      block_of[axis][std::size_t(i)] = local / side_;
      offset[axis][std::size_t(i)] = local % side_;
    }
    blocks[axis] = block_of[axis][std::size_t(n - 1)] + 1;
  }
  constexpr int kMaxBlocks = kMaxFindVoxelsSide;  // per axis: n voxels touch at most n blocks
  std::array<int, kMaxBlocks * kMaxBlocks * kMaxBlocks> base;  // first voxel index, or -1
  for (int bz = 0; bz < blocks.z(); ++bz)
    for (int by = 0; by < blocks.y(); ++by)
      for (int bx = 0; bx < blocks.x(); ++bx) {
        const int index = find_block(first_block + Eigen::Vector3i(bx, by, bz), cache);
        base[std::size_t((bz * kMaxBlocks + by) * kMaxBlocks + bx)] =
            index < 0 ? -1 : index * voxels_per_block_;
      }
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const int block = base[std::size_t(
            (block_of[2][std::size_t(z)] * kMaxBlocks + block_of[1][std::size_t(y)]) * kMaxBlocks +
            block_of[0][std::size_t(x)])];
        const int local = (offset[2][std::size_t(z)] * side_ + offset[1][std::size_t(y)]) * side_ +
                          offset[0][std::size_t(x)];
        voxels[(z * n + y) * n + x] = block < 0 ? -1 : block + local;
      }
}

int ObservationGrid::find(const Eigen::Vector3f& p, BlockCache* cache) const {
  const Eigen::Vector3f v = p / float(params_.voxel_size_m);
  return find_voxel({int(std::floor(v.x())), int(std::floor(v.y())), int(std::floor(v.z()))},
                    cache);
}

Eigen::Vector3i ObservationGrid::voxel_coordinates(int v) const {
  const int block = v / voxels_per_block_, local = v % voxels_per_block_;
  return hash_.block(block) * side_ + local_coordinates(local);
}

void ObservationGrid::allocate(const ImageF& depth_m, const Intrinsics& intrinsics,
                               const Pose& camera_to_world, int frame) {
  const int stride = params_.allocation_stride_px;
  const float inverse_block = float(1.0 / params_.block_size_m);
  const Eigen::Matrix3f rotation = camera_to_world.linear().cast<float>();
  const Eigen::Vector3f translation = camera_to_world.translation().cast<float>();
  const std::size_t rows = std::size_t((depth_m.height() + stride - 1) / stride);
  // The blocks under each chunk of rows, and their pool indices (kAbsent: new), found in
  // parallel; the new ones are then inserted, and the frame's blocks listed, in row order on one
  // thread. Pool indices, and so the order of the frame's voxels that the segments' reservoirs
  // and samples follow, then do not depend on how the threads were scheduled: a run gives the
  // same result on any number of threads.
  constexpr std::size_t kRowsPerChunk = 4;
  chunk_blocks_.resize((rows + kRowsPerChunk - 1) / kRowsPerChunk);
  tbb::enumerable_thread_specific<std::vector<Eigen::Vector3i>> buffers;
  parallel_for(chunk_blocks_.size(), [&](std::size_t chunk) {
    fusion::PendingBlocks pending(hash_, buffers.local());
    for (std::size_t row = chunk * kRowsPerChunk; row < std::min(rows, (chunk + 1) * kRowsPerChunk);
         ++row) {
      const int y = int(row) * stride;
      for (int x = 0; x < depth_m.width(); x += stride) {
        const float z = depth_m.at(x, y, 0);
        if (!(z > 0) || !std::isfinite(z)) continue;
        const Eigen::Vector3f p =
            rotation * intrinsics.back_project(x, y, z).cast<float>() + translation;
        const Eigen::Vector3f b = p * inverse_block;
        pending.add(int(std::floor(b.x())), int(std::floor(b.y())), int(std::floor(b.z())));
      }
    }
    std::vector<std::pair<Eigen::Vector3i, int>>& found = chunk_blocks_[chunk];
    found.clear();
    for (const Eigen::Vector3i& block : pending.blocks())
      found.emplace_back(block, hash_.find(block));
  });
  frame_blocks_.clear();
  for (const auto& found : chunk_blocks_)
    for (auto [block, index] : found) {
      if (index == fusion::VoxelBlockHash::kAbsent) {
        index = hash_.insert(block).index;
        if (index < 0)
          throw Error("observation grid", "voxel_capacity",
                      "pool of " + std::to_string(hash_.capacity() * voxels_per_block_) +
                          " voxels is exhausted; raise it (--obs-voxels) or use a coarser grid");
      }
      if (block_last_frame_[index].exchange(frame, std::memory_order_relaxed) != frame)
        frame_blocks_.push_back(index);
    }
}

void ObservationGrid::refresh_surface(int v, const Eigen::Vector3f& centre, int frame,
                                      fusion::TsdfSampler& sampler) {
  // Newton steps onto the zero level set along the (central-difference) SDF gradient: two from
  // the voxel centre, one from the previous surface point once there is one.
  const bool refine = has_surface_[v];
  const float half = 0.5f * float(params_.voxel_size_m);
  Eigen::Vector3f p = refine ? position_[v] : centre, gradient = Eigen::Vector3f::Zero();
  bool found = false;
  for (int step = refine ? 1 : 0; step < 2; ++step) {
    float sdf = 0;
    if (!sampler.trilinear_with_gradient(p, sdf, gradient)) break;
    const float norm = gradient.norm();
    if (!(norm > 0.1f)) break;
    p -= sdf / (norm * norm) * gradient;
    found = true;
    // A first step that lands a whole voxel outside means the surface misses this voxel: the
    // second step only corrects for curvature, so it is skipped (most tries are such misses).
    if (step == 0 && (p - centre).cwiseAbs().maxCoeff() > 2 * half) break;
  }
  // The surface must pass through this voxel (its neighbours own the rest of the patch).
  found = found && ((p - centre).cwiseAbs().maxCoeff() <= half * 1.001f);
  has_surface_[v] = found;
  // Most voxels without surface are empty space beside it in a block the surface crosses, and
  // stay so: retrying them every few frames was most of the observation stage's TSDF reads.
  const int misses =
      found ? 0 : std::min(surface_misses_[v] + 1, params_.surface_retry_doublings + 1);
  // A settled surface changes little between refreshes: re-reading the TSDF and refitting its
  // plane every few frames is wasted.
  const bool settled =
      found && refine &&
      (p - position_[v]).norm() < float(params_.settled_shift * params_.voxel_size_m);
  const int settled_count =
      settled ? std::min(surface_settled_[v] + 1, params_.settled_refresh_doublings) : 0;
  surface_misses_[v] = std::uint8_t(misses);
  surface_settled_[v] = std::uint8_t(settled_count);
  next_refresh_frame_[v] = next_refresh(frame, misses, settled_count);
  if (!found) return;
  position_[v] = p;
  normal_[v] = gradient.normalized();
}

void ObservationGrid::prefetch_neighbour_slots(std::size_t slot) const {
  const Eigen::Vector3i block = hash_.block(frame_blocks_[slot]);
  for (int i = 0; i < 27; ++i) hash_.prefetch(block + neighbour_offset(i));
}

void ObservationGrid::find_neighbours(std::size_t slot, NeighbourBlocks& around) const {
  const Eigen::Vector3i block = hash_.block(frame_blocks_[slot]);
  for (int i = 0; i < 27; ++i) around[std::size_t(i)] = hash_.find(block + neighbour_offset(i));
}

void ObservationGrid::prefetch_refit_state(const NeighbourBlocks& around) const {
  const std::size_t voxels = voxels_per_block_;
  for (int i = 0; i < 27; ++i) {
    if (around[std::size_t(i)] < 0) continue;
    const std::size_t first = std::size_t(around[std::size_t(i)]) * voxels;
    prefetch_lines(has_surface_.get() + first, voxels * sizeof(bool));
    if (i != kOwnBlock) continue;  // the refit reads all of its own voxels' state
    prefetch_lines(next_refresh_frame_.get() + first, voxels * sizeof(int));
    prefetch_lines(surface_settled_.get() + first, voxels * sizeof(std::uint8_t));
    prefetch_lines(position_.get() + first, voxels * sizeof(Eigen::Vector3f));
    prefetch_lines(normal_.get() + first, voxels * sizeof(Eigen::Vector3f));
  }
}

void ObservationGrid::fit_normals_to_neighbours(std::size_t slot, int frame,
                                                const NeighbourBlocks& around) {
  const int block = frame_blocks_[slot];
  const int first_voxel = block * voxels_per_block_;
  const auto refreshed = [&](int v) {  // in this frame's collect(), and found the surface
    return has_surface_[v] && next_refresh_frame_[v] == next_refresh(frame, 0, surface_settled_[v]);
  };
  const Eigen::Vector3i block_coordinates = hash_.block(block);
  const Eigen::Vector3i origin = (block_coordinates - Eigen::Vector3i::Ones()) * side_;
  // Neighbours more than 30 degrees off the voxel's tangent plane belong to another face.
  const float max_off_plane = std::sin(float(M_PI) / 6);

  for (int local = 0; local < voxels_per_block_; ++local) {
    const int v = first_voxel + local;
    if (!refreshed(v)) continue;
    const Eigen::Vector3f p = position_[v], gradient_normal = normal_[v];
    const Eigen::Vector3i centre = voxel_coordinates(v);
    std::array<Eigen::Vector3f, 27> points;  // relative to p: better conditioned
    int count = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i voxel = centre + Eigen::Vector3i(dx, dy, dz) - origin;
          const Eigen::Vector3i b = voxel / side_;  // within the 3^3 blocks: non-negative
          const int index = around[(b.z() * 3 + b.y()) * 3 + b.x()];
          if (index < 0) continue;
          const int u = voxel_index(index, voxel - b * side_);
          if (!has_surface_[u]) continue;
          const Eigen::Vector3f d = position_[u] - p;
          if (std::fabs(d.dot(gradient_normal)) <= max_off_plane * d.norm()) points[count++] = d;
        }
    if (const auto normal = fit_plane(points.data(), count, gradient_normal)) normal_[v] = *normal;
  }
}

const std::vector<VisibleVoxel>& ObservationGrid::collect(
    const ImageF& depth_m, const ImageF& colour, const Intrinsics& intrinsics,
    const Pose& camera_to_world, float exposure, const fusion::TsdfVolume& geometry, int frame) {
  if (depth_m.channels() != 1 || depth_m.width() != intrinsics.width ||
      depth_m.height() != intrinsics.height || colour.channels() != 3 || !colour.same_size(depth_m))
    throw Error("observation grid", "frame " + std::to_string(frame),
                "needs a 1-channel depth and a 3-channel colour image of the intrinsics' size");
  if (!(exposure > 0)) throw Error("observation grid", "exposure", "must be positive");
  allocate(depth_m, intrinsics, camera_to_world, frame);

  const Pose world_to_camera = camera_to_world.inverse();
  const Eigen::Matrix3f rotation = world_to_camera.linear().cast<float>();
  const Eigen::Vector3f translation = world_to_camera.translation().cast<float>();
  const Eigen::Vector3f camera_centre = camera_to_world.translation().cast<float>();
  const float inverse_exposure = 1.0f / exposure;
  const int capacity = params_.observations_per_voxel;
  const float spacing_cosine =
      params_.min_observation_spacing_deg > 0
          ? float(std::cos(params_.min_observation_spacing_deg * std::numbers::pi / 180))
          : 2.0f;  // no dot product of unit vectors exceeds it
  const int spacing_max_frames =
      params_.spacing_max_frames > 0 ? params_.spacing_max_frames : std::numeric_limits<int>::max();
  const int width = depth_m.width(), height = depth_m.height();
  const float* depth = depth_m.plane(0);

  // Each frame block's observed voxels go to its own range of voxels_per_block_ entries, in
  // voxel order, and are gathered after the pass, so no per-voxel array is cleared and scanned
  // each frame (at 1 cm only 13 % of the voxels have a surface).
  const std::size_t entries = frame_blocks_.size() * voxels_per_block_;
  if (visible_by_block_.size() < entries) visible_by_block_.resize(entries);
  visible_in_block_.assign(frame_blocks_.size(), 0);
  // The voxels go in two passes: the first refreshes surfaces, tests visibility and prefetches
  // the observation slots of the visible voxels; the second inserts. Insertion reads every
  // stored direction of a voxel (~1 KB), so the misses of a batch of voxels then overlap
  // instead of stalling voxel after voxel. A batch spans blocks (at 2 cm a block has only 8
  // voxels, and batches of one block left the misses little time). The next block's per-voxel
  // state is prefetched too: the blocks of a frame lie scattered in the pools.
  struct Seen {
    int voxel, visible_index, pixel;  // pixel: y * width + x
    Eigen::Vector3f direction;
  };
  constexpr int kBatch = 128, kInsertFrom = 32;  // voxels pending, and at least this many
  const std::size_t blocks = frame_blocks_.size();
  const float inverse_geometry_voxel = 1.0f / float(geometry.params().voxel_size_m);
  block_refreshed_.assign(blocks, 0);
  parallel_for_chunks(blocks, 16, [&](std::size_t begin, std::size_t end) {
    fusion::TsdfSampler sampler(geometry);  // its block cache serves each block's voxels
    struct Projection {
      int pixel;  // y * width + x; -1: no surface, or not in front of the camera and in the image
      float z;
    };
    std::vector<Projection> projections(voxels_per_block_);
    std::array<Seen, kBatch> seen;
    int pending = 0;
    // geometry_reads_due() of the blocks ahead, by slot % 4.
    std::array<GeometryReads, 4> due_reads;
    const auto insert_pending = [&] {
      for (int i = 0; i < pending; ++i) {
        const Seen& voxel = seen[i];
        const int v = voxel.voxel;
        const Observation observation(
            Eigen::Vector3f(colour.plane(0)[voxel.pixel], colour.plane(1)[voxel.pixel],
                            colour.plane(2)[voxel.pixel]) *
                inverse_exposure,
            voxel.direction, std::uint32_t(frame));
        if (observation_set_[v] == 0)
          observation_set_[v] = 1 + observation_sets_used_.fetch_add(1, std::memory_order_relaxed);
        const std::size_t first = first_slot(v);
        observation_count_[v] = std::uint8_t(
            insert_observation(observations_.get() + first,
                               {nearest_similarity_.get() + first, nearest_slot_.get() + first},
                               observation_count_[v], capacity, observation));
        newest_[v] = {voxel.direction, frame};
        visible_by_block_[voxel.visible_index] = {v, voxel.pixel};
      }
      pending = 0;
    };
    for (std::size_t slot = begin; slot < end; ++slot) {
      if (pending >= kInsertFrom || pending + voxels_per_block_ > kBatch) insert_pending();
      // A software pipeline over the blocks. Four ahead: the voxels' refresh frames and surface
      // flags. Three ahead: the rest of their state. Two ahead: the hash slots of the geometry
      // blocks that the due refreshes' stencils reach, including neighbours of the block under
      // this one. One ahead: the lines of those blocks' distances that the stencils read. With only
      // the block under this one asked for, just before use, the refreshes stalled on the TSDF's
      // reads (cubes: 1,410 TSC cycles per refresh; 760 with the pipeline).
      const auto ahead = [&](std::size_t n) {
        return frame_blocks_[std::min(slot + n, blocks - 1)];
      };
      const auto find_reads = [&](std::size_t n) {
        GeometryReads& reads = due_reads[(slot + n) % 4];
        geometry_reads_due(ahead(n), frame, inverse_geometry_voxel, reads);
        for (int i = 0; i < reads.count; ++i)
          geometry.hash().prefetch(reads.blocks[std::size_t(i)]);
      };
      const auto prefetch_reads = [&](std::size_t n) {
        const GeometryReads& reads = due_reads[(slot + n) % 4];
        for (int i = 0; i < reads.count; ++i) {
          const int index = geometry.hash().find(reads.blocks[std::size_t(i)]);
          if (index >= 0) geometry.prefetch_distance_lines(index, reads.lines[std::size_t(i)]);
        }
      };
      if (slot == begin) {
        for (std::size_t n = 0; n < 4; ++n) prefetch_surface_flags(ahead(n));
        for (std::size_t n = 0; n < 3; ++n) prefetch_voxel_state(ahead(n));
        for (std::size_t n = 0; n < 2; ++n) find_reads(n);
        prefetch_reads(0);
      }
      prefetch_surface_flags(ahead(4));
      prefetch_voxel_state(ahead(3));
      find_reads(2);
      prefetch_reads(1);
      const int block = ahead(0);
      const Eigen::Vector3i first_voxel = hash_.block(block) * side_;
      // Two passes over the block's voxels: the first refreshes surfaces, projects them and asks
      // for the depth under each; the second tests visibility. Voxels come in block order, which
      // scatters their pixels over images larger than the cache, so the depth and colour reads
      // are prefetched.
      for (int local = 0; local < voxels_per_block_; ++local) {
        const Eigen::Vector3i offset = local_coordinates(local);
        const int v = block * voxels_per_block_ + local;
        if (frame >= next_refresh_frame_[v]) {
          refresh_surface(v, voxel_centre(first_voxel + offset), frame, sampler);
          if (has_surface_[v]) block_refreshed_[slot] = 1;
        }
        Projection& projection = projections[local];
        projection.pixel = -1;
        if (!has_surface_[v]) continue;
        // In front of the camera and in the image.
        const Eigen::Vector3f q = rotation * position_[v] + translation;
        if (!(q.z() > 0)) continue;
        const float u = float(intrinsics.fx) * q.x() / q.z() + float(intrinsics.cx);
        const float w = float(intrinsics.fy) * q.y() / q.z() + float(intrinsics.cy);
        int x, y;
        if (!fusion::nearest_pixel(u, w, width, height, x, y)) continue;
        projection.pixel = y * width + x;
        projection.z = q.z();
        __builtin_prefetch(depth + projection.pixel);
      }
      int observed = 0;  // of this block's voxels, so far
      for (int local = 0; local < voxels_per_block_; ++local) {
        const Projection& projection = projections[local];
        if (projection.pixel < 0) continue;
        const int v = block * voxels_per_block_ + local;
        // Facing the camera and not occluded.
        const float measured = depth[projection.pixel];
        const float tolerance =
            float(params_.depth_tolerance_m) +
            float(params_.depth_tolerance_sigmas) * kinect_axial_noise_m(projection.z);
        if (!(measured > 0) || std::fabs(measured - projection.z) > tolerance) continue;
        const Eigen::Vector3f direction = (camera_centre - position_[v]).normalized();
        if (normal_[v].dot(direction) < float(params_.min_view_cosine)) continue;
        if (observation_count_[v] > 0 && direction.dot(newest_[v].direction) > spacing_cosine &&
            frame - newest_[v].frame < spacing_max_frames) {
          visible_by_block_[slot * voxels_per_block_ + observed++] = {v, projection.pixel};
          continue;
        }
        prefetch_observations(v, true);
        // Its colour is read at insertion, a batch later: ask for it now (three planes).
        for (int channel = 0; channel < 3; ++channel)
          __builtin_prefetch(colour.plane(channel) + projection.pixel);
        seen[pending++] = {v, int(slot) * voxels_per_block_ + observed++, projection.pixel,
                           direction};
      }
      visible_in_block_[slot] = observed;
    }
    insert_pending();
  });
  // After all refreshes: a plane fit reads its neighbours' surface points, which the pass above
  // may be writing on another thread. Only the blocks with a refreshed surface: testing every
  // block's voxels read their state from memory again (11,700 blocks per frame on cubes, most
  // without a refresh).
  if (params_.normal_from_neighbours) {
    refit_blocks_.clear();
    for (std::size_t slot = 0; slot < blocks; ++slot)
      if (block_refreshed_[slot]) refit_blocks_.push_back(slot);
    // A software pipeline over the blocks: two ahead, the hash slots of the 3^3 blocks around;
    // one ahead, their look-ups and the state the refit reads.
    parallel_for_chunks(refit_blocks_.size(), 16, [&](std::size_t begin, std::size_t end) {
      std::array<NeighbourBlocks, 2> around;
      for (std::size_t i = begin; i < std::min(begin + 2, end); ++i)
        prefetch_neighbour_slots(refit_blocks_[i]);
      find_neighbours(refit_blocks_[begin], around[0]);
      prefetch_refit_state(around[0]);
      for (std::size_t i = begin; i < end; ++i) {
        const std::size_t current = (i - begin) % 2, next = 1 - current;
        if (i + 2 < end) prefetch_neighbour_slots(refit_blocks_[i + 2]);
        if (i + 1 < end) {
          find_neighbours(refit_blocks_[i + 1], around[next]);
          prefetch_refit_state(around[next]);
        }
        fit_normals_to_neighbours(refit_blocks_[i], frame, around[current]);
      }
    });
  }
  visible_.clear();
  for (std::size_t slot = 0; slot < blocks; ++slot) {
    const auto first = visible_by_block_.begin() + std::ptrdiff_t(slot * voxels_per_block_);
    visible_.insert(visible_.end(), first, first + visible_in_block_[slot]);
  }
  return visible_;
}

}  // namespace glint::reflectance
