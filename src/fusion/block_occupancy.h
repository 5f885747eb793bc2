#pragma once
// BlockOccupancy: which blocks of a TSDF volume are allocated, one bit per block over the
// bounding box of the allocated ones. A ray cast crosses far more empty blocks than allocated
// ones (office: 1.65 M samples per view in unallocated space), and asking the block hash about
// each missed the caches: the hash table is megabytes of slots, the bit array a few hundred
// kilobytes. Coarser arrays mark the cells of 2^l blocks per side (l = 1 .. kLevels) that hold
// any: a ray crosses the largest empty cell around it in one step instead of one per block
// (office at 2 cm: 113 M samples in unallocated space over 40 frames with cells of 4^3 blocks
// alone, 48 M with the levels). A snapshot: blocks allocated afterwards are not in it.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "fusion/tsdf_volume.h"

namespace glint::fusion {

class BlockOccupancy {
 public:
  // Bit arrays above this many bits (a bounding box of 2^30 blocks: 43 km^3 of 4 cm blocks) are
  // not built; may_hold() then answers true for every block.
  static constexpr std::uint64_t kMaxBits = std::uint64_t{1} << 30;
  // Cells of 2 up to 2^kLevels blocks per side (5.1 m of 5 mm voxels at the top).
  static constexpr int kLevels = 7;

  explicit BlockOccupancy(const TsdfVolume& volume);

  // False only where block (bx, by, bz) is surely not allocated.
  bool may_hold(int bx, int by, int bz) const {
    if (levels_.empty()) return !built_empty_;
    const std::uint64_t x = std::uint64_t(std::int64_t(bx) - low_.x());
    const std::uint64_t y = std::uint64_t(std::int64_t(by) - low_.y());
    const std::uint64_t z = std::uint64_t(std::int64_t(bz) - low_.z());
    if (x >= std::uint64_t(size_.x()) || y >= std::uint64_t(size_.y()) ||
        z >= std::uint64_t(size_.z()))
      return false;
    return levels_[0].holds(Eigen::Vector3i(int(x), int(y), int(z)));
  }

  // The blocks [first, last] (inclusive) around block (bx, by, bz) that surely hold no allocated
  // one: the largest cell holding it that holds none, a slab of the space outside the bounding
  // box where the block lies there (unbounded along the other axes: INT_MIN / INT_MAX), else the
  // block alone, which must not be allocated. Only the block where no bit array was built.
  void empty_region(int bx, int by, int bz, Eigen::Vector3i& first, Eigen::Vector3i& last) const;

  // The blocks [low, high] (block coordinates, inclusive) that hold every allocated one; false
  // where there is none or the bit array was not built (no box is known).
  bool bounds(Eigen::Vector3i& low, Eigen::Vector3i& high) const {
    if (levels_.empty()) return false;
    low = low_;
    high = low_ + size_ - Eigen::Vector3i::Ones();
    return true;
  }

 private:
  // The cells of one level: 2^level blocks per side (level 0: the blocks), one bit per cell over
  // the box.
  struct CellLevel {
    Eigen::Vector3i cells = Eigen::Vector3i::Zero();  // cells per axis
    std::vector<std::uint64_t> words;

    std::uint64_t bit(const Eigen::Vector3i& c) const {
      return (std::uint64_t(c.z()) * std::uint64_t(cells.y()) + std::uint64_t(c.y())) *
                 std::uint64_t(cells.x()) +
             std::uint64_t(c.x());
    }
    bool holds(const Eigen::Vector3i& c) const {
      const std::uint64_t b = bit(c);
      return words[b >> 6] >> (b & 63) & 1;
    }
    void mark(const Eigen::Vector3i& c) {
      const std::uint64_t b = bit(c);
      words[b >> 6] |= std::uint64_t{1} << (b & 63);
    }
  };

  Eigen::Vector3i low_ = Eigen::Vector3i::Zero(), size_ = Eigen::Vector3i::Zero();
  std::vector<CellLevel> levels_;  // levels_[l]: cells of 2^l blocks per side, l = 0 .. kLevels
  bool built_empty_ = false;       // the volume held no block
};

}  // namespace glint::fusion
