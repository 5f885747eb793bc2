#include "fusion/voxel_block_hash.h"

#include <gtest/gtest.h>

#include <atomic>
#include <set>

#include "core/parallel.h"

namespace glint::fusion {
namespace {

TEST(VoxelBlockHash, InsertThenFindAndReinsertKeepsTheIndex) {
  VoxelBlockHash hash(100);
  EXPECT_GE(hash.slot_count(), 200u);
  const auto a = hash.insert({1, -2, 3});
  const auto b = hash.insert({-1000, 5, 0});
  EXPECT_TRUE(a.inserted);
  EXPECT_TRUE(b.inserted);
  EXPECT_NE(a.index, b.index);
  EXPECT_EQ(hash.find({1, -2, 3}), a.index);
  EXPECT_EQ(hash.find({-1000, 5, 0}), b.index);
  EXPECT_EQ(hash.find({1, 2, 3}), VoxelBlockHash::kAbsent);
  const auto again = hash.insert({1, -2, 3});
  EXPECT_FALSE(again.inserted);
  EXPECT_EQ(again.index, a.index);
  EXPECT_EQ(hash.size(), 2u);
  EXPECT_EQ(hash.block(b.index), Eigen::Vector3i(-1000, 5, 0));
}

TEST(PendingBlocks, SkipsRepeatsOfRecentBlocksAndKeepsTheirOrder) {
  const VoxelBlockHash hash(100);
  std::vector<Eigen::Vector3i> buffer{{9, 9, 9}};  // a previous chunk's: cleared
  PendingBlocks pending(hash, buffer);
  for (const Eigen::Vector3i& block : {Eigen::Vector3i(1, 2, 3), Eigen::Vector3i(1, 2, 3),
                                       Eigen::Vector3i(-4, 0, 7), Eigen::Vector3i(1, 2, 3)})
    pending.add(block.x(), block.y(), block.z());
  EXPECT_EQ(pending.blocks(), (std::vector<Eigen::Vector3i>{{1, 2, 3}, {-4, 0, 7}}));
  EXPECT_EQ(hash.size(), 0u);  // gathering inserts nothing
}

TEST(VoxelBlockHash, CollidingKeysAreAllFound) {
  VoxelBlockHash hash(64);
  const std::uint32_t mask = static_cast<std::uint32_t>(hash.slot_count() - 1);
  // Blocks whose Teschner hash lands in the same slot.
  const std::uint32_t target = teschner_hash(0, 0, 0) & mask;
  std::vector<Eigen::Vector3i> colliding;
  for (int x = 0; colliding.size() < 10 && x < 100000; ++x) {
    if ((teschner_hash(x, 7, -3) & mask) == target) colliding.push_back({x, 7, -3});
  }
  ASSERT_EQ(colliding.size(), 10u);
  for (const auto& block : colliding) EXPECT_TRUE(hash.insert(block).inserted);
  for (std::size_t i = 0; i < colliding.size(); ++i) EXPECT_EQ(hash.find(colliding[i]), int(i));
  EXPECT_EQ(hash.find({0, 0, 0}), VoxelBlockHash::kAbsent);
}

TEST(VoxelBlockHash, FullPoolReportsInsteadOfOverwriting) {
  VoxelBlockHash hash(3);
  for (int i = 0; i < 3; ++i) EXPECT_GE(hash.insert({i, 0, 0}).index, 0);
  EXPECT_EQ(hash.insert({9, 9, 9}).index, VoxelBlockHash::kPoolFull);
  EXPECT_EQ(hash.size(), 3u);
  EXPECT_EQ(hash.find({1, 0, 0}), 1);
}

TEST(VoxelBlockHash, ConcurrentInsertionsGiveOneIndexPerBlock) {
  VoxelBlockHash hash(20000);
  std::atomic<int> created{0};
  // Every block inserted by several threads at once.
  parallel_for(80000, [&](std::size_t i) {
    const int n = static_cast<int>(i % 20000);
    if (hash.insert({n % 31, n / 31, -n}).inserted) ++created;
  });
  EXPECT_EQ(created.load(), 20000);
  EXPECT_EQ(hash.size(), 20000u);
  std::set<int> indices;
  for (int n = 0; n < 20000; ++n) indices.insert(hash.find({n % 31, n / 31, -n}));
  EXPECT_EQ(indices.size(), 20000u);
  EXPECT_EQ(*indices.begin(), 0);
}

}  // namespace
}  // namespace glint::fusion
