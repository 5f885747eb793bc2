#pragma once
// BlockOccupancy: which blocks of a TSDF volume are allocated, one bit per block over the
// bounding box of the allocated ones, and one per region of 4^3 and of 16^3 blocks. A ray cast
// crosses far more empty blocks than allocated ones (office: 1.65 M samples per view in
// unallocated space): asking the block hash about each missed the caches (the hash table is
// megabytes of slots, the bit arrays a few hundred kilobytes), and the empty regions let a ray
// leave 16 or 64 cm of empty space at once (a tile of pixels whose rays start near the camera,
// because some block near the camera projects onto it, crosses metres of it). A snapshot:
// blocks allocated afterwards are not in it.
#include <Eigen/Core>
#include <bit>
#include <cstdint>
#include <vector>

#include "fusion/tsdf_volume.h"

namespace glint::fusion {

class BlockOccupancy {
 public:
  // Bit arrays above this many bits (a bounding box of 2^30 blocks: 43 km^3 of 4 cm blocks) are
  // not built; may_hold() then answers true for every block.
  static constexpr std::uint64_t kMaxBits = std::uint64_t{1} << 30;
  // Regions are cubes of 4^3 and 16^3 blocks, aligned to multiples of their side.
  static constexpr int kSmallRegion = 4, kLargeRegion = 16;

  explicit BlockOccupancy(const TsdfVolume& volume);

  // False only where block (bx, by, bz) is surely not allocated.
  bool may_hold(int bx, int by, int bz) const {
    if (!blocks_.built()) return !empty_volume_;
    return blocks_.test(bx, by, bz);
  }
  // For a block that is not allocated: the side, in blocks, of the largest aligned cube around
  // it that holds no allocated block either: kLargeRegion, kSmallRegion or 1.
  int empty_side(int bx, int by, int bz) const {
    if (!large_.built()) return empty_volume_ ? kLargeRegion : 1;
    if (!large_.test(region(bx, kLargeRegion), region(by, kLargeRegion), region(bz, kLargeRegion)))
      return kLargeRegion;
    if (!small_.test(region(bx, kSmallRegion), region(by, kSmallRegion), region(bz, kSmallRegion)))
      return kSmallRegion;
    return 1;
  }
  // The region of side `side` (a power of 2) holding block b, along one axis.
  static int region(int b, int side) { return b >> std::countr_zero(unsigned(side)); }

 private:
  // A bit per cell of a box of integer cells; cells outside it read as clear.
  struct BitGrid {
    Eigen::Vector3i low = Eigen::Vector3i::Zero(), size = Eigen::Vector3i::Zero();
    std::vector<std::uint64_t> words;

    bool built() const { return !words.empty(); }
    // Sized for the box [low, high]; false (and left unbuilt) above kMaxBits.
    bool cover(const Eigen::Vector3i& low, const Eigen::Vector3i& high);
    void set(const Eigen::Vector3i& cell) {
      const std::uint64_t bit = index(cell.x() - low.x(), cell.y() - low.y(), cell.z() - low.z());
      words[bit >> 6] |= std::uint64_t{1} << (bit & 63);
    }
    bool test(int x, int y, int z) const {
      const std::uint64_t dx = std::uint64_t(std::int64_t(x) - low.x());
      const std::uint64_t dy = std::uint64_t(std::int64_t(y) - low.y());
      const std::uint64_t dz = std::uint64_t(std::int64_t(z) - low.z());
      if (dx >= std::uint64_t(size.x()) || dy >= std::uint64_t(size.y()) ||
          dz >= std::uint64_t(size.z()))
        return false;
      const std::uint64_t bit = index(dx, dy, dz);
      return words[bit >> 6] >> (bit & 63) & 1;
    }
    std::uint64_t index(std::uint64_t x, std::uint64_t y, std::uint64_t z) const {
      return (z * std::uint64_t(size.y()) + y) * std::uint64_t(size.x()) + x;
    }
  };

  BitGrid blocks_, small_, large_;
  bool empty_volume_ = false;  // the volume held no block
};

}  // namespace glint::fusion
