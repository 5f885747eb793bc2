#include "fusion/block_occupancy.h"

namespace glint::fusion {

bool BlockOccupancy::BitGrid::cover(const Eigen::Vector3i& from, const Eigen::Vector3i& to) {
  const Eigen::Matrix<std::uint64_t, 3, 1> extent =
      (to - from).cast<std::int64_t>().cast<std::uint64_t>() +
      Eigen::Matrix<std::uint64_t, 3, 1>::Ones();
  const std::uint64_t bits = extent.x() * extent.y() * extent.z();
  if (bits > kMaxBits) return false;
  low = from;
  size = extent.cast<int>();
  words.assign((bits + 63) / 64, 0);
  return true;
}

BlockOccupancy::BlockOccupancy(const TsdfVolume& volume) {
  const VoxelBlockHash& hash = volume.hash();
  const std::size_t count = volume.block_count();
  if (count == 0) {
    empty_volume_ = true;
    return;
  }
  Eigen::Vector3i low = hash.block(0), high = low;
  for (std::size_t i = 1; i < count; ++i) {
    low = low.cwiseMin(hash.block(int(i)));
    high = high.cwiseMax(hash.block(int(i)));
  }
  const auto region_of = [](const Eigen::Vector3i& b, int side) {
    return Eigen::Vector3i(region(b.x(), side), region(b.y(), side), region(b.z(), side));
  };
  // Without the block bits (a bounding box too large), may_hold() says "maybe" to every block
  // and empty_side() answers 1.
  if (!blocks_.cover(low, high)) return;
  small_.cover(region_of(low, kSmallRegion), region_of(high, kSmallRegion));
  large_.cover(region_of(low, kLargeRegion), region_of(high, kLargeRegion));
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Vector3i& b = hash.block(int(i));
    blocks_.set(b);
    small_.set(region_of(b, kSmallRegion));
    large_.set(region_of(b, kLargeRegion));
  }
}

}  // namespace glint::fusion
