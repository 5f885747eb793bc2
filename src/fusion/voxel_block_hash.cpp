#include "fusion/voxel_block_hash.h"

#include <algorithm>
#include <bit>
#include <memory>

namespace glint::fusion {

VoxelBlockHash::VoxelBlockHash(std::size_t block_capacity)
    : capacity_(block_capacity),
      slots_(std::bit_ceil(std::max<std::size_t>(2 * block_capacity, 16))),
      slots_table_(make_pool<Slot>(slots_, "voxel block hash")),
      blocks_(block_capacity) {
  std::uninitialized_default_construct_n(slots_table_.get(), slots_);
  clear();
}

void VoxelBlockHash::clear() {
  for (std::size_t i = 0; i < slots_; ++i) {
    slots_table_[i].key.store(kEmptyKey, std::memory_order_relaxed);
    slots_table_[i].value.store(kPending, std::memory_order_relaxed);
  }
  used_.store(0);
}

std::size_t VoxelBlockHash::size() const { return std::min(used_.load(), capacity_); }

VoxelBlockHash::Insertion VoxelBlockHash::insert(const Eigen::Vector3i& block) {
  const std::uint64_t key = pack_block_key(block.x(), block.y(), block.z());
  const std::size_t mask = slots_ - 1;
  std::size_t slot = teschner_hash(block.x(), block.y(), block.z()) & mask;
  for (std::size_t probe = 0; probe < slots_; ++probe, slot = (slot + 1) & mask) {
    std::uint64_t current = slots_table_[slot].key.load(std::memory_order_acquire);
    if (current == kEmptyKey &&
        slots_table_[slot].key.compare_exchange_strong(current, key, std::memory_order_acq_rel)) {
      const std::size_t index = used_.fetch_add(1);
      const int value = index < capacity_ ? static_cast<int>(index) : kPoolFull;
      if (value >= 0) blocks_[value] = block;
      slots_table_[slot].value.store(value, std::memory_order_release);
      return {value, value >= 0};
    }
    if (current == key) {
      int value;
      while ((value = slots_table_[slot].value.load(std::memory_order_acquire)) == kPending) {
      }
      return {value, false};
    }
  }
  return {kPoolFull, false};
}

int VoxelBlockHash::find(const Eigen::Vector3i& block) const {
  const std::uint64_t key = pack_block_key(block.x(), block.y(), block.z());
  const std::size_t mask = slots_ - 1;
  std::size_t slot = teschner_hash(block.x(), block.y(), block.z()) & mask;
  for (std::size_t probe = 0; probe < slots_; ++probe, slot = (slot + 1) & mask) {
    const std::uint64_t current = slots_table_[slot].key.load(std::memory_order_relaxed);
    if (current == key) {
      const int value = slots_table_[slot].value.load(std::memory_order_relaxed);
      return value >= 0 ? value : kAbsent;
    }
    if (current == kEmptyKey) return kAbsent;
  }
  return kAbsent;
}

}  // namespace glint::fusion
