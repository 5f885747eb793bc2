#pragma once
// BlockIndexCache: the pool indices of the blocks looked up last, one entry per residue of the
// block coordinates modulo kSide along each axis, so that a sweep of nearby look-ups (a ray's
// stencils, a rendering's neighbouring pixels) finds most of them without the block hash, whose
// table is far larger than the caches. kSide consecutive blocks along each axis fit at once.
#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace glint::fusion {

template <int kSide>
class BlockIndexCache {
  static_assert(kSide == 2 || kSide == 4, "a power of 2, and few entries");
  static constexpr int kEntries = kSide * kSide * kSide;

 public:
  // The cached index of `block`, else find(block), which is then cached.
  template <class Find>
  int operator()(const Eigen::Vector3i& block, Find&& find) {
    constexpr int mask = kSide - 1;
    const int entry =
        ((block.z() & mask) * kSide + (block.y() & mask)) * kSide + (block.x() & mask);
    if (!held_[entry] || coordinates_[entry] != block) {
      coordinates_[entry] = block;
      held_[entry] = true;
      index_[entry] = find(block);
    }
    return index_[entry];
  }

 private:
  std::array<Eigen::Vector3i, kEntries> coordinates_;
  std::array<int, kEntries> index_;
  std::array<bool, kEntries> held_{};
};

}  // namespace glint::fusion
