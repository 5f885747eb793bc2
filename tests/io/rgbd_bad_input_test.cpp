// RGB-D readers on broken copies of the fixtures: every failure is a glint::Error that names
// the offending file.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/image_io.h"
#include "io/rgbd_sequence.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

namespace fs = std::filesystem;
using test::error_of;

// A fresh copy of fixture layout `name` in the test's scratch folder.
std::string copy_of(const std::string& name) {
  const fs::path target = test::scratch_folder() / name;
  fs::copy(std::string(GLINT_TEST_DATA_DIR) + "/rgbd/" + name, target,
           fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  return target.string();
}

TEST(RgbdBadInput, UnknownLayoutNamesTheFolder) {
  const std::string folder = test::scratch_folder().string();
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(folder); }).file(), folder);
  EXPECT_THROW(open_rgbd_sequence(folder + "/does-not-exist"), Error);
}

TEST(RgbdBadInput, MissingFrameNamesTheImage) {
  const std::string folder = copy_of("glint");
  fs::remove(folder + "/depth/000001.png");
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(folder); }).file(), folder + "/depth/000001.png");

  const std::string scenes = copy_of("7scenes");
  const std::string colour = scenes + "/rgbd-frames/frame-000151.color.png";
  fs::remove(colour);
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(scenes); }).file(), colour);
}

TEST(RgbdBadInput, FrameDeletedAfterOpeningNamesTheImage) {
  const std::string folder = copy_of("redwood");
  const RgbdSequence sequence = open_rgbd_sequence(folder);
  fs::remove(sequence.frames[2].depth_path);
  EXPECT_EQ(error_of([&] { read_rgbd_frame(sequence, 2); }).file(), sequence.frames[2].depth_path);
  EXPECT_THROW(read_rgbd_frame(sequence, 7), Error);
}

TEST(RgbdBadInput, SizeMismatchNamesTheImage) {
  const std::string folder = copy_of("glint");
  const std::string colour = folder + "/rgb/000002.png";
  write_image(colour, ImageF(8, 6, 3, 0.5f));
  const RgbdSequence sequence = open_rgbd_sequence(folder);
  EXPECT_NO_THROW(read_rgbd_frame(sequence, 1));
  const Error error = error_of([&] { read_rgbd_frame(sequence, 2); });
  EXPECT_EQ(error.file(), colour);
  EXPECT_NE(error.reason().find("8x6"), std::string::npos) << error.reason();
}

TEST(RgbdBadInput, EightBitOrCorruptDepthIsRejected) {
  const std::string folder = copy_of("tum");
  const RgbdSequence sequence = open_rgbd_sequence(folder);
  write_image(sequence.frames[0].depth_path, ImageF(16, 12, 1, 0.5f), PngDepth::eight);
  EXPECT_EQ(error_of([&] { read_rgbd_frame(sequence, 0); }).file(), sequence.frames[0].depth_path);
  test::write_text(sequence.frames[1].depth_path, "not a png");
  EXPECT_EQ(error_of([&] { read_rgbd_frame(sequence, 1); }).file(), sequence.frames[1].depth_path);
}

TEST(RgbdBadInput, TruncatedColourIsRejected) {
  const std::string folder = copy_of("redwood");
  const RgbdSequence sequence = open_rgbd_sequence(folder);
  const std::string& colour = sequence.frames[1].colour_path;
  const std::string bytes = test::read_text(colour);
  test::write_text(colour, bytes.substr(0, bytes.size() - 20));
  const Error error = error_of([&] { read_rgbd_frame(sequence, 1); });
  EXPECT_EQ(error.file(), colour);
  EXPECT_NE(error.reason().find("truncated PNG"), std::string::npos) << error.reason();
}

TEST(RgbdBadInput, MalformedPoseFilesNameFileAndLine) {
  const std::string scenes = copy_of("7scenes");
  const std::string pose = scenes + "/rgbd-frames/frame-000150.pose.txt";
  test::write_text(pose, "1 0 0 0\n0 1 0 0\n0 0 x 0\n0 0 0 1\n");
  Error error = error_of([&] { open_rgbd_sequence(scenes); });
  EXPECT_EQ(error.file(), pose);
  EXPECT_EQ(error.element(), "line 3");
  test::write_text(pose, "2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");  // not a rotation
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(scenes); }).file(), pose);

  const std::string redwood = copy_of("redwood");
  test::write_text(redwood + "/trajectory.log", "0 0 1\n1 0 0 0\n0 1 0 0\n");
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(redwood); }).file(), redwood + "/trajectory.log");

  const std::string tum = copy_of("tum");
  test::write_text(tum + "/groundtruth.txt", "100 0 0 0 0 0 0\n");
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(tum); }).file(), tum + "/groundtruth.txt");
}

TEST(RgbdBadInput, MalformedListsAndIntrinsics) {
  const std::string tum = copy_of("tum");
  test::write_text(tum + "/rgb.txt", "abc rgb/1.png\n");
  const Error error = error_of([&] { open_rgbd_sequence(tum); });
  EXPECT_EQ(error.file(), tum + "/rgb.txt");
  EXPECT_EQ(error.element(), "line 1");

  const std::string glint = copy_of("glint");
  test::write_text(glint + "/intrinsics.json", R"({"width": 16, "height": 12, "fx": 20})");
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(glint); }).file(), glint + "/intrinsics.json");

  const std::string scenes = copy_of("7scenes");
  test::write_text(scenes + "/camera-intrinsics.txt", "20 0 7.5\n0 20 5.5\n");
  EXPECT_EQ(error_of([&] { open_rgbd_sequence(scenes); }).file(),
            scenes + "/camera-intrinsics.txt");
}

}  // namespace
}  // namespace glint::io
