// Segment propagation on a two-object scene: two walls at different depths, seen by a camera
// that slides between frames, with per-frame labels whose numbering changes from frame to frame.
#include "reflectance/segment_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "core/error.h"
#include "fusion/integrate.h"
#include "reflectance/depth_segmentation.h"

namespace glint::reflectance {
namespace {

const Intrinsics kCamera{96, 72, 70.0, 70.0, 47.5, 35.5};

// Left of world x = 0 a wall at z = 1.0 m, right of it a wall at z = 1.4 m (two objects).
ImageF two_walls_depth(double camera_x) {
  ImageF depth(kCamera.width, kCamera.height, 1);
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      const Eigen::Vector3d ray = kCamera.ray(x, y);
      const double left_z = 1.0, right_z = 1.4;
      depth.at(x, y, 0) = float(camera_x + ray.x() * left_z < 0 ? left_z : right_z);
    }
  return depth;
}

// Which wall a world point belongs to.
int wall_of(const Eigen::Vector3f& p) { return p.z() < 1.2f ? 1 : 2; }

struct Scene {
  fusion::TsdfVolume geometry{[] {
    fusion::VolumeParams params;
    params.voxel_size_m = 0.005;
    params.block_capacity = 1 << 13;
    return params;
  }()};
  ObservationGrid grid{ObservationGridParams{.voxel_capacity = 1 << 15}};
  fusion::VisibleBlocks blocks;
  ImageF colour{kCamera.width, kCamera.height, 3, 0.3f};

  const std::vector<VisibleVoxel>& frame(int index, double camera_x, ImageF& depth) {
    depth = two_walls_depth(camera_x);
    Pose pose = Pose::Identity();
    pose.translation().x() = camera_x;
    fusion::integrate(geometry, depth, colour, kCamera, pose, blocks);
    return grid.collect(depth, colour, kCamera, pose, 1.0f, geometry, index);
  }
};

TEST(SegmentMap, PropagatesTwoObjectsAcrossRenumberedFrames) {
  Scene scene;
  SegmentMap segments;
  for (int index = 0; index < 6; ++index) {
    ImageF depth;
    const double camera_x = -0.05 + 0.02 * index;
    const auto& visible = scene.frame(index, camera_x, depth);
    // Per-frame labels from the depth image, renumbered every other frame (as a per-frame
    // segmentation would number them arbitrarily).
    Image<std::int32_t> labels(kCamera.width, kCamera.height, 1);
    for (int y = 0; y < kCamera.height; ++y)
      for (int x = 0; x < kCamera.width; ++x) {
        const int wall = depth.at(x, y, 0) < 1.2f ? 1 : 2;
        labels.at(x, y, 0) = index % 2 ? 3 - wall : wall + 4;
      }
    segments.update(scene.grid, visible, labels, false);
    EXPECT_EQ(segments.frame_segments().size(), 2u) << "frame " << index;
  }
  EXPECT_EQ(segments.max_segment_id(), 2) << "no segment beyond the two objects";
  // Every labelled voxel carries the id of its wall's segment, one id per wall.
  std::map<int, std::set<int>> ids_of_wall;
  for (int v = 0; v < int(scene.grid.voxel_count()); ++v)
    if (scene.grid.segment(v) > 0)
      ids_of_wall[wall_of(scene.grid.position(v))].insert(scene.grid.segment(v));
  ASSERT_EQ(ids_of_wall.size(), 2u);
  EXPECT_EQ(ids_of_wall[1].size(), 1u);
  EXPECT_EQ(ids_of_wall[2].size(), 1u);
  EXPECT_NE(*ids_of_wall[1].begin(), *ids_of_wall[2].begin());

  // Sampling returns distinct voxels of the asked segment only.
  std::mt19937_64 random(3);
  const int id = *ids_of_wall[1].begin();
  std::vector<int> sampled(25);
  const int count = segments.sample(scene.grid, id, 25, 1, random, sampled.data());
  EXPECT_EQ(count, 25);
  std::set<int> distinct(sampled.begin(), sampled.begin() + count);
  EXPECT_EQ(distinct.size(), std::size_t(count));
  for (int v : distinct) EXPECT_EQ(scene.grid.segment(v), id);
}

TEST(SegmentMap, OneSurfaceSeenInTwoPiecesIsMerged) {
  Scene scene;
  SegmentMap segments;
  for (int index = 0; index < 3; ++index) {
    ImageF depth;
    const auto& visible = scene.frame(index, 0.0, depth);
    // Frame 0 splits the near wall at image column 20 into labels 1 and 2; later frames see it
    // whole (label 1). The far wall is label 3 throughout.
    Image<std::int32_t> labels(kCamera.width, kCamera.height, 1);
    for (int y = 0; y < kCamera.height; ++y)
      for (int x = 0; x < kCamera.width; ++x)
        labels.at(x, y, 0) = depth.at(x, y, 0) > 1.2f ? 3 : (index == 0 && x >= 20 ? 2 : 1);
    segments.update(scene.grid, visible, labels, false);
  }
  EXPECT_EQ(segments.merges(), 1);
  EXPECT_EQ(segments.frame_segments().size(), 2u);
  std::set<int> near_ids;
  for (int v = 0; v < int(scene.grid.voxel_count()); ++v)
    if (scene.grid.segment(v) > 0 && wall_of(scene.grid.position(v)) == 1)
      near_ids.insert(scene.grid.segment(v));
  EXPECT_EQ(near_ids.size(), 1u);
}

TEST(SegmentMap, DepthSegmentationSeparatesTheWallsAndStaysConsistent) {
  Scene scene;
  SegmentMap segments;
  DepthSegmentationParams params;
  params.min_segment_px = 50;
  for (int index = 0; index < 4; ++index) {
    ImageF depth;
    const auto& visible = scene.frame(index, -0.04 + 0.02 * index, depth);
    segments.update(scene.grid, visible, segment_depth(depth, kCamera, params).labels, false);
  }
  EXPECT_EQ(segments.max_segment_id(), 2);
}

TEST(SegmentMap, GroundTruthIdsAreUsedAsTheyAre) {
  Scene scene;
  SegmentMap segments;
  ImageF depth;
  const auto& visible = scene.frame(0, 0.0, depth);
  Image<std::int32_t> ids(kCamera.width, kCamera.height, 1);
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) ids.at(x, y, 0) = depth.at(x, y, 0) < 1.2f ? 7 : 9;
  segments.update(scene.grid, visible, ids, true);
  EXPECT_EQ(segments.frame_segments(), (std::vector<int>{7, 9}));
  for (const VisibleVoxel& seen : visible)
    EXPECT_EQ(scene.grid.segment(seen.voxel),
              wall_of(scene.grid.position(seen.voxel)) == 1 ? 7 : 9);
}

// A segment that grows by more than its buffer holds in one frame: the buffer stays a uniform
// sample of all its members, so the well-observed early ones can still be drawn (a ring that
// overwrote its oldest entries held only the newest voxels, each seen once).
TEST(SegmentMap, BufferStaysAUniformSampleOfASegmentGrowingFasterThanItHolds) {
  Scene scene;
  constexpr int kCapacity = 256;
  SegmentMap segments(SegmentMapParams{.reservoir_capacity = kCapacity});
  std::set<int> early;  // joined in the first three frames (camera still)
  std::set<int> late;   // joined in the last one (camera moved 0.6 m)
  for (int index = 0; index < 4; ++index) {
    ImageF depth;
    const auto& visible = scene.frame(index, index < 3 ? 0.0 : 0.6, depth);
    const Image<std::int32_t> ids(kCamera.width, kCamera.height, 1, 7);  // one segment
    for (const VisibleVoxel& seen : visible)
      if (scene.grid.segment(seen.voxel) == 0) (index < 3 ? early : late).insert(seen.voxel);
    segments.update(scene.grid, visible, ids, true);
  }
  ASSERT_GT(early.size(), std::size_t(2 * kCapacity));
  ASSERT_GT(late.size(), std::size_t(kCapacity));
  EXPECT_EQ(segments.reservoir_size(7), kCapacity);

  std::mt19937_64 random(5);
  std::vector<int> sampled(kCapacity);
  // Every entry, each checked once: the buffer's composition.
  const int count = segments.sample(scene.grid, 7, kCapacity, 1, random, sampled.data());
  ASSERT_EQ(count, kCapacity);
  const double early_share =
      double(std::count_if(sampled.begin(), sampled.end(), [&](int v) { return early.count(v); })) /
      count;
  const double expected = double(early.size()) / double(early.size() + late.size());
  // Binomial spread of 256 draws: a standard deviation under 0.032.
  EXPECT_NEAR(early_share, expected, 0.12);
  // The early voxels were observed in three frames: a sample needing three finds them.
  EXPECT_EQ(segments.sample(scene.grid, 7, 25, 3, random, sampled.data()), 25);
}

TEST(SegmentMap, RejectsAnEmptyBuffer) {
  EXPECT_THROW(SegmentMap(SegmentMapParams{.reservoir_capacity = 0}), Error);
}

}  // namespace
}  // namespace glint::reflectance
