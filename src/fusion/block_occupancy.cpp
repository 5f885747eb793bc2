#include "fusion/block_occupancy.h"

namespace glint::fusion {

BlockOccupancy::BlockOccupancy(const TsdfVolume& volume) {
  const VoxelBlockHash& hash = volume.hash();
  const std::size_t blocks = volume.block_count();
  if (blocks == 0) {
    built_empty_ = true;
    return;
  }
  Eigen::Vector3i high = hash.block(0);
  low_ = high;
  for (std::size_t i = 1; i < blocks; ++i) {
    low_ = low_.cwiseMin(hash.block(int(i)));
    high = high.cwiseMax(hash.block(int(i)));
  }
  const Eigen::Matrix<std::uint64_t, 3, 1> size =
      (high - low_).cast<std::int64_t>().cast<std::uint64_t>() +
      Eigen::Matrix<std::uint64_t, 3, 1>::Ones();
  if (size.x() * size.y() * size.z() > kMaxBits) return;  // may_hold() says "maybe" to all
  size_ = size.cast<int>();
  words_.assign((size.x() * size.y() * size.z() + 63) / 64, 0);
  for (std::size_t i = 0; i < blocks; ++i) {
    const Eigen::Vector3i b = hash.block(int(i)) - low_;
    const std::uint64_t bit =
        (std::uint64_t(b.z()) * size.y() + std::uint64_t(b.y())) * size.x() + std::uint64_t(b.x());
    words_[bit >> 6] |= std::uint64_t{1} << (bit & 63);
  }
}

}  // namespace glint::fusion
