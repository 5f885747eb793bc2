// Every RGB-D layout on the tiny fixtures of tests/data/rgbd (written by make_fixtures.py:
// 16x12 frames of a wall at 1.0 m + 0.01 m * column + 0.002 m * frame, camera i at x = 0.01 i).
#include "io/rgbd_sequence.h"

#include <gtest/gtest.h>

#include <cmath>

namespace glint::io {
namespace {

std::string rgbd_fixture(const std::string& name) {
  return std::string(GLINT_TEST_DATA_DIR) + "/rgbd/" + name;
}

double srgb8_to_linear(int value) {
  const double c = value / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// The fixture scene, whatever the layout: intrinsics, depth, colour and poses.
void expect_fixture_sequence(const RgbdSequence& sequence, std::size_t frames) {
  EXPECT_EQ(sequence.intrinsics.width, 16);
  EXPECT_EQ(sequence.intrinsics.height, 12);
  EXPECT_DOUBLE_EQ(sequence.intrinsics.fx, 20.0);
  EXPECT_DOUBLE_EQ(sequence.intrinsics.cy, 5.5);
  ASSERT_EQ(sequence.frames.size(), frames);
  for (std::size_t i = 0; i < frames; ++i) {
    const RgbdFrame frame = read_rgbd_frame(sequence, i);
    ASSERT_EQ(frame.depth_m.width(), 16);
    ASSERT_EQ(frame.colour.channels(), 3);
    EXPECT_EQ(frame.depth_m.at(0, 0, 0), 0.0f) << "stored 0 = no measurement";
    EXPECT_NEAR(frame.depth_m.at(5, 3, 0), 1.0 + 0.05 + 0.002 * i, 1e-4);
    EXPECT_NEAR(frame.colour.at(5, 3, 0), srgb8_to_linear(80), 1e-6);  // red = 16 x
    EXPECT_NEAR(frame.colour.at(5, 3, 1), srgb8_to_linear(48), 1e-6);  // green = 16 y
    EXPECT_NEAR(frame.colour.at(5, 3, 2), srgb8_to_linear(40 * static_cast<int>(i)), 1e-6);
    ASSERT_TRUE(frame.ground_truth.has_value());
    EXPECT_NEAR(frame.ground_truth->translation().x(), 0.01 * i, 1e-9);
    EXPECT_TRUE(frame.ground_truth->linear().isIdentity(1e-9));
  }
}

TEST(RgbdSequence, GlintSyntheticLayout) {
  const RgbdSequence sequence = open_rgbd_sequence(rgbd_fixture("glint"));
  EXPECT_EQ(sequence.format, "glint");
  EXPECT_DOUBLE_EQ(sequence.depth_units_per_metre, 1000);
  expect_fixture_sequence(sequence, 3);
  EXPECT_NEAR(sequence.frames[2].timestamp_s, 2 / 30.0, 1e-6);
}

TEST(RgbdSequence, TumListsAssociatedByTimestampAndDepthScale5000) {
  const RgbdSequence sequence = open_rgbd_sequence(rgbd_fixture("tum"));
  EXPECT_EQ(sequence.format, "tum");
  EXPECT_DOUBLE_EQ(sequence.depth_units_per_metre, 5000);
  // The fourth depth image has no colour image within 0.02 s: skipped.
  expect_fixture_sequence(sequence, 3);
}

TEST(RgbdSequence, SevenScenesFramesWithPoseFiles) {
  const RgbdSequence sequence = open_rgbd_sequence(rgbd_fixture("7scenes"));
  EXPECT_EQ(sequence.format, "7scenes");
  expect_fixture_sequence(sequence, 3);
  EXPECT_NEAR(sequence.frames[0].timestamp_s, 150 / 30.0, 1e-9);
}

TEST(RgbdSequence, RedwoodFoldersWithLogTrajectory) {
  const RgbdSequence sequence = open_rgbd_sequence(rgbd_fixture("redwood"));
  EXPECT_EQ(sequence.format, "redwood");
  expect_fixture_sequence(sequence, 3);
}

TEST(RgbdSequence, EachLayoutHasItsOwnOpener) {
  EXPECT_EQ(open_glint_sequence(rgbd_fixture("glint")).frames.size(), 3u);
  EXPECT_EQ(open_tum_sequence(rgbd_fixture("tum")).frames.size(), 3u);
  EXPECT_EQ(open_7scenes_sequence(rgbd_fixture("7scenes")).frames.size(), 3u);
  EXPECT_EQ(open_redwood_sequence(rgbd_fixture("redwood")).frames.size(), 3u);
  EXPECT_TRUE(open_tum_sequence(rgbd_fixture("tum")).has_ground_truth());
}

}  // namespace
}  // namespace glint::io
