#pragma once
// VoxelBlockHash: a fixed-capacity spatial hash from integer block coordinates to indices into a
// block pool (VoxelHashing, Niessner et al. 2013 §4.1). Open addressing with linear probing over
// a flat table of 2^k slots (at least twice the block capacity, so probes stay short), keys
// hashed with Teschner et al. 2003: (x*73856093 ^ y*19349669 ^ z*83492791) mod slots.
//
// insert() is lock-free and may run concurrently with other insert() calls (keys are claimed
// with compare-and-swap, pool indices handed out by an atomic counter); find() may run
// concurrently with other find() calls but not with insert(). Block coordinates must lie in
// [-2^20, 2^20) on each axis (+-5 km at 5 mm voxels).
#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/pool_memory.h"
#include "fusion/host_device.h"

namespace glint::fusion {

GLINT_HOST_DEVICE inline std::uint32_t teschner_hash(int x, int y, int z) {
  return (static_cast<std::uint32_t>(x) * 73856093u) ^ (static_cast<std::uint32_t>(y) * 19349669u) ^
         (static_cast<std::uint32_t>(z) * 83492791u);
}

// 21 bits per axis, offset by 2^20, in one 64-bit key.
GLINT_HOST_DEVICE inline std::uint64_t pack_block_key(int x, int y, int z) {
  constexpr std::int64_t offset = 1 << 20;
  return (static_cast<std::uint64_t>(x + offset) << 42) |
         (static_cast<std::uint64_t>(y + offset) << 21) | static_cast<std::uint64_t>(z + offset);
}

class VoxelBlockHash {
 public:
  static constexpr int kAbsent = -1;
  static constexpr int kPoolFull = -2;

  explicit VoxelBlockHash(std::size_t block_capacity);

  struct Insertion {
    int index = kAbsent;    // pool index, or kPoolFull when the pool is exhausted
    bool inserted = false;  // true for the one caller that created the entry
  };
  // The block's pool index, creating the entry when absent.
  Insertion insert(const Eigen::Vector3i& block);
  // The block's pool index or kAbsent.
  int find(const Eigen::Vector3i& block) const;
  // Asks for the cache line of the block's first probe slot ahead of an insert() or find(): the
  // table is far larger than the caches, so nearly every first probe misses.
  void prefetch(const Eigen::Vector3i& block) const {
    __builtin_prefetch(
        &slots_table_[teschner_hash(block.x(), block.y(), block.z()) & (slots_ - 1)]);
  }

  std::size_t size() const;  // blocks in the pool
  std::size_t capacity() const { return capacity_; }
  std::size_t slot_count() const { return slots_; }
  // Block coordinates of pool entry `index` (< size()).
  const Eigen::Vector3i& block(int index) const { return blocks_[index]; }
  void clear();

 private:
  static constexpr std::uint64_t kEmptyKey = ~std::uint64_t{0};
  static constexpr int kPending = -3;  // a key claimed whose index is not yet published

  std::size_t capacity_;
  std::size_t slots_;
  // Key and pool index side by side: a probe touches one cache line.
  struct Slot {
    std::atomic<std::uint64_t> key;
    std::atomic<int> value;
  };
  PoolArray<Slot> slots_table_;
  std::vector<Eigen::Vector3i> blocks_;
  std::atomic<std::size_t> used_{0};
};

// The blocks a chunk of image rows touches, gathered before any is inserted into `hash`:
// neighbouring pixels mostly hit the same blocks, so a small direct-mapped cache of the blocks
// already gathered skips most repeats, and each new block's hash slot is prefetched when it is
// gathered, so the cache misses of the inserts that follow overlap instead of stalling one
// after another. `blocks` is the caller's (per-thread) buffer, cleared here.
class PendingBlocks {
 public:
  PendingBlocks(const VoxelBlockHash& hash, std::vector<Eigen::Vector3i>& blocks)
      : hash_(hash), blocks_(blocks) {
    recent_.fill(~std::uint64_t{0});
    blocks_.clear();
  }
  void add(int x, int y, int z) {
    std::uint64_t& slot = recent_[teschner_hash(x, y, z) & (recent_.size() - 1)];
    const std::uint64_t key = pack_block_key(x, y, z);
    if (slot == key) return;
    slot = key;
    blocks_.emplace_back(x, y, z);
    hash_.prefetch(blocks_.back());
  }
  const std::vector<Eigen::Vector3i>& blocks() const { return blocks_; }

 private:
  const VoxelBlockHash& hash_;
  std::vector<Eigen::Vector3i>& blocks_;
  std::array<std::uint64_t, 256> recent_;
};

}  // namespace glint::fusion
