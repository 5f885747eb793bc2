#include "fusion/block_occupancy.h"

#include <climits>

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
  levels_.resize(kLevels + 1);
  for (int level = 0; level <= kLevels; ++level) {
    CellLevel& cells = levels_[std::size_t(level)];
    const int side = 1 << level;
    cells.cells = (size_.array() + (side - 1)) / side;
    cells.words.assign(
        (std::uint64_t(cells.cells.x()) * cells.cells.y() * cells.cells.z() + 63) / 64, 0);
  }
  for (std::size_t i = 0; i < blocks; ++i) {
    const Eigen::Vector3i b = hash.block(int(i)) - low_;
    for (int level = 0; level <= kLevels; ++level)
      levels_[std::size_t(level)].mark(b.unaryExpr([level](int v) { return v >> level; }));
  }
}

void BlockOccupancy::empty_region(int bx, int by, int bz, Eigen::Vector3i& first,
                                  Eigen::Vector3i& last) const {
  const Eigen::Vector3i block(bx, by, bz);
  first = last = block;
  if (levels_.empty()) return;
  const Eigen::Vector3i high = low_ + size_ - Eigen::Vector3i::Ones();
  for (int axis = 0; axis < 3; ++axis) {
    if (block[axis] >= low_[axis] && block[axis] <= high[axis]) continue;
    first.setConstant(INT_MIN);
    last.setConstant(INT_MAX);
    if (block[axis] < low_[axis]) {
      last[axis] = low_[axis] - 1;
    } else {
      first[axis] = high[axis] + 1;
    }
    return;
  }
  // A cell is empty only where the cells inside it are: climb while the next one up is empty.
  const Eigen::Vector3i offset = block - low_;
  for (int level = 1; level <= kLevels; ++level) {
    const Eigen::Vector3i c = offset.unaryExpr([level](int v) { return v >> level; });
    if (levels_[std::size_t(level)].holds(c)) return;
    first = low_ + c * (1 << level);
    last = first + Eigen::Vector3i::Constant((1 << level) - 1);
  }
}

}  // namespace glint::fusion
