// TsdfSampler: trilinear reads and the shared-stencil value + gradient that the observation grid
// uses to put its voxels on the surface.
#include "fusion/tsdf_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <vector>

#include "fusion_test_support.h"

namespace glint::fusion {
namespace {

// 1 cm voxels (8 cm blocks).
VolumeParams centimetre_voxels() {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.block_capacity = 20000;
  return params;
}

TEST(TsdfSampler, GradientOfALinearFieldIsItsNormalAcrossBlockFaces) {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  TsdfVolume volume(centimetre_voxels());
  test::fill_analytic(
      volume, [&](const Eigen::Vector3d& p) { return normal.dot(p) - 0.02; }, 0.5, 0.3);
  TsdfSampler sampler(volume);
  // Just inside a block corner (blocks are 8 cm), so the stencil spans eight blocks.
  for (const Eigen::Vector3f& p :
       {Eigen::Vector3f(0.0812f, 0.0795f, 0.0803f), Eigen::Vector3f(-0.0013f, 0.0437f, -0.0791f)}) {
    float value = 0;
    Eigen::Vector3f gradient;
    ASSERT_TRUE(sampler.trilinear_with_gradient(p, value, gradient));
    EXPECT_NEAR(value, normal.cast<float>().dot(p) - 0.02f, 1e-5f);
    EXPECT_LT((gradient - normal.cast<float>()).norm(), 1e-4f) << gradient.transpose();
  }
}

TEST(TsdfSampler, ACellAcrossBlockCornersReadsEachVoxelFromItsBlock) {
  const Eigen::Vector3d normal = Eigen::Vector3d(-0.6, 0.2, 0.7).normalized();
  TsdfVolume volume(centimetre_voxels());
  test::fill_analytic(
      volume, [&](const Eigen::Vector3d& p) { return normal.dot(p) + 0.01; }, 0.5, 0.3);
  TsdfSampler sampler(volume);
  // Cells whose corners lie in 1, 2, 4 and 8 blocks (8 cm blocks, voxel centres at 1 cm steps).
  for (const Eigen::Vector3f& p :
       {Eigen::Vector3f(0.0321f, 0.0452f, 0.0213f), Eigen::Vector3f(0.0752f, 0.0421f, 0.0133f),
        Eigen::Vector3f(0.0752f, -0.0047f, 0.0133f), Eigen::Vector3f(-0.0044f, 0.0761f, 0.0788f)}) {
    float value = 0;
    ASSERT_TRUE(sampler.trilinear(p, value)) << p.transpose();
    EXPECT_NEAR(value, normal.cast<float>().dot(p) + 0.01f, 1e-5f) << p.transpose();
  }
  // A cell reaching into an unallocated block is not read.
  TsdfVolume single(centimetre_voxels());
  const int block = single.allocate({0, 0, 0});
  ASSERT_GE(block, 0);
  std::fill_n(single.sdf_m(block), kVoxelsPerBlock, 0.02f);
  std::fill_n(single.weight(block), kVoxelsPerBlock, std::uint8_t{1});
  TsdfSampler reader(single);
  float value = 0;
  EXPECT_TRUE(reader.trilinear(Eigen::Vector3f(0.0652f, 0.0421f, 0.0133f), value));
  EXPECT_FLOAT_EQ(value, 0.02f);
  EXPECT_FALSE(reader.trilinear(Eigen::Vector3f(0.0752f, 0.0421f, 0.0133f), value));
  EXPECT_FALSE(reader.trilinear(Eigen::Vector3f(0.0652f, -0.0047f, 0.0133f), value));
}

TEST(TsdfSampler, GradientIsTheCentralDifferenceOfTrilinearReads) {
  const Eigen::Vector3d centre(0.01, -0.02, 0.03);
  TsdfVolume volume(centimetre_voxels());
  test::fill_analytic(
      volume, [&](const Eigen::Vector3d& p) { return (p - centre).norm() - 0.2; }, 0.5, 0.3);
  TsdfSampler sampler(volume);
  const Eigen::Vector3f p(0.1734f, 0.0561f, 0.1049f);
  float value = 0, expected = 0;
  Eigen::Vector3f gradient;
  ASSERT_TRUE(sampler.trilinear_with_gradient(p, value, gradient));
  ASSERT_TRUE(sampler.trilinear(p, expected));
  EXPECT_FLOAT_EQ(value, expected);
  const float h = 0.01f;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3f step = Eigen::Vector3f::Zero();
    step[axis] = h;
    float plus = 0, minus = 0;
    ASSERT_TRUE(sampler.trilinear(p + step, plus) && sampler.trilinear(p - step, minus));
    EXPECT_NEAR(gradient[axis], (plus - minus) / (2 * h), 1e-3f) << axis;
  }
}

TEST(TsdfSampler, AnUnobservedFaceNeighbourFailsTheGradientOnly) {
  TsdfVolume volume(centimetre_voxels());
  test::fill_analytic(
      volume, [](const Eigen::Vector3d& p) { return p.z() - 0.013; }, 0.5, 0.3);
  const Eigen::Vector3f p(0.0145f, 0.0155f, 0.0125f);  // cell (1, 1, 1)
  // Voxel (3, 1, 1): in the +x face stencil, not in the cell's own eight.
  const int block = volume.hash().find({0, 0, 0});
  ASSERT_GE(block, 0);
  const int forgotten = (1 * kBlockSide + 1) * kBlockSide + 3;
  volume.sdf_m(block)[forgotten] = kUnobservedSdf;
  volume.weight(block)[forgotten] = 0;
  TsdfSampler sampler(volume);
  float value = 0;
  Eigen::Vector3f gradient;
  EXPECT_TRUE(sampler.trilinear(p, value));
  EXPECT_FALSE(sampler.trilinear_with_gradient(p, value, gradient));
}

TEST(TsdfSampler, ABlockOfTheSameParityIsLookedUpAfresh) {
  // Blocks 0 and 2 along x share a cache entry; only block 0 is allocated.
  TsdfVolume volume(centimetre_voxels());
  ASSERT_GE(volume.allocate({0, 0, 0}), 0);
  const int block = volume.hash().find({0, 0, 0});
  TsdfSampler sampler(volume);
  float sdf = 0;
  EXPECT_EQ(sampler.voxel(3, 3, 3, sdf), TsdfSampler::Sample::unobserved) << "not yet fused";
  std::fill_n(volume.sdf_m(block), kVoxelsPerBlock, 0.01f);
  std::fill_n(volume.weight(block), kVoxelsPerBlock, std::uint8_t{1});
  EXPECT_EQ(sampler.voxel(3, 3, 3, sdf), TsdfSampler::Sample::observed);
  EXPECT_EQ(sampler.voxel(19, 3, 3, sdf), TsdfSampler::Sample::unallocated);
  EXPECT_EQ(sampler.voxel(3, 3, 3, sdf), TsdfSampler::Sample::observed);
}

// The lines that a stencil's prefetch asks for (the observation grid's surface refreshes):
// exactly those holding a voxel of rows y0..y1 in slices z0..z1, by the voxels' byte offsets.
TEST(TsdfVolume, DistanceLinesAreTheLinesHoldingTheRowsOfTheSlices) {
  EXPECT_EQ(TsdfVolume::distance_lines(0, 1, 0, 0), 0x1u);
  EXPECT_EQ(TsdfVolume::distance_lines(1, 2, 0, 0), 0x3u);
  EXPECT_EQ(TsdfVolume::distance_lines(0, 7, 1, 1), 0xf0u);
  EXPECT_EQ(TsdfVolume::distance_lines(0, 7, 0, 7), 0xffffffffu);
  for (int y0 = 0; y0 < kBlockSide; ++y0)
    for (int y1 = y0; y1 < kBlockSide; ++y1)
      for (int z0 = 0; z0 < kBlockSide; z0 += 3)
        for (int z1 = z0; z1 < kBlockSide; z1 += 2) {
          std::uint32_t expected = 0;
          for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y)
              for (int x = 0; x < kBlockSide; ++x)
                expected |= 1u << (voxel_in_block(x, y, z) * int(sizeof(float)) / 64);
          EXPECT_EQ(TsdfVolume::distance_lines(y0, y1, z0, z1), expected)
              << "rows " << y0 << ".." << y1 << ", slices " << z0 << ".." << z1;
        }
}

TEST(BlockOccupancy, EmptyRegionsHoldNoAllocatedBlock) {
  TsdfVolume volume(centimetre_voxels());
  const std::vector<Eigen::Vector3i> allocated = {{-9, 0, 2}, {4, -1, 2}, {0, 5, -6}, {1, 1, 1}};
  for (const Eigen::Vector3i& b : allocated) ASSERT_GE(volume.allocate(b), 0);
  const BlockOccupancy occupancy(volume);
  Eigen::Vector3i low, high;
  ASSERT_TRUE(occupancy.bounds(low, high));
  // Whether the cube of `side` blocks aligned on the box's corner that holds `block` holds an
  // allocated block.
  const auto cell_holds_one = [&](const Eigen::Vector3i& block, int side) {
    const Eigen::Vector3i first = low + ((block - low) / side) * side;
    return std::any_of(allocated.begin(), allocated.end(), [&](const Eigen::Vector3i& b) {
      return ((first.array() <= b.array()) && (b.array() < first.array() + side)).all();
    });
  };
  int whole_cells = 0, slabs = 0, larger_cells = 0;
  for (int z = -12; z <= 12; ++z)
    for (int y = -12; y <= 12; ++y)
      for (int x = -12; x <= 12; ++x) {
        if (occupancy.may_hold(x, y, z)) continue;
        Eigen::Vector3i first, last;
        occupancy.empty_region(x, y, z, first, last);
        const Eigen::Vector3i block(x, y, z);
        ASSERT_TRUE((first.array() <= block.array()).all() && (block.array() <= last.array()).all())
            << x << " " << y << " " << z;
        for (const Eigen::Vector3i& b : allocated)
          ASSERT_FALSE((first.array() <= b.array()).all() && (b.array() <= last.array()).all())
              << "the region of " << x << " " << y << " " << z << " holds " << b.transpose();
        const bool unbounded = (first.array() == INT_MIN).any() || (last.array() == INT_MAX).any();
        slabs += unbounded;
        if (unbounded) continue;
        // Inside the box: the largest empty cell of 2^l blocks per side, l >= 0.
        const int side = last.x() - first.x() + 1;
        ASSERT_EQ(last - first, Eigen::Vector3i::Constant(side - 1));
        const Eigen::Vector3i offset = first - low;
        ASSERT_TRUE(offset.x() % side == 0 && offset.y() % side == 0 && offset.z() % side == 0);
        ASSERT_TRUE(cell_holds_one(block, 2 * side))
            << "the region of " << x << " " << y << " " << z << " could be larger than " << side;
        whole_cells += side > 1;
        larger_cells += side > 4;
      }
  EXPECT_GT(whole_cells, 100);  // cells of blocks between the blocks
  EXPECT_GT(larger_cells, 0);   // cells of 8^3 blocks and more
  EXPECT_GT(slabs, 1000);       // around the box of the blocks

  // Without a bit array (an empty volume's), only the block itself.
  TsdfVolume none(centimetre_voxels());
  Eigen::Vector3i first, last;
  BlockOccupancy(none).empty_region(3, 4, 5, first, last);
  EXPECT_EQ(first, Eigen::Vector3i(3, 4, 5));
  EXPECT_EQ(last, Eigen::Vector3i(3, 4, 5));
}

TEST(BlockOccupancy, HoldsEveryAllocatedBlockAndRulesOutTheRest) {
  TsdfVolume volume(centimetre_voxels());
  const BlockOccupancy empty(volume);
  EXPECT_FALSE(empty.may_hold(0, 0, 0)) << "a volume without blocks holds none";
  const std::vector<Eigen::Vector3i> allocated = {{-3, 0, 2}, {4, -1, 2}, {0, 5, -6}, {1, 1, 1}};
  for (const Eigen::Vector3i& b : allocated) ASSERT_GE(volume.allocate(b), 0);
  const BlockOccupancy occupancy(volume);
  int held = 0;
  for (int z = -8; z <= 8; ++z)
    for (int y = -8; y <= 8; ++y)
      for (int x = -8; x <= 8; ++x) {
        const bool is_allocated = volume.hash().find({x, y, z}) >= 0;
        EXPECT_EQ(occupancy.may_hold(x, y, z), is_allocated) << x << " " << y << " " << z;
        held += is_allocated;
      }
  EXPECT_EQ(held, int(allocated.size()));
  EXPECT_FALSE(occupancy.may_hold(1 << 19, 0, 0));
  EXPECT_FALSE(occupancy.may_hold(-(1 << 19), 0, 0));

  // A sampler told of the occupancy reads the same samples as one that asks the hash.
  const int block = volume.hash().find({1, 1, 1});
  std::fill_n(volume.sdf_m(block), kVoxelsPerBlock, 0.02f);
  std::fill_n(volume.weight(block), kVoxelsPerBlock, std::uint8_t{1});
  TsdfSampler plain(volume), told(volume, &occupancy);
  for (int x = 0; x < 40; ++x) {
    float a = 0, b = 0;
    ASSERT_EQ(plain.voxel(x, 12, 12, a), told.voxel(x, 12, 12, b)) << x;
    EXPECT_EQ(a, b);
  }
}

}  // namespace
}  // namespace glint::fusion
