// The RGB-D readers bound what sizes fusion's loops: intrinsics against the image size (a
// principal point of 1e9 made `glint fuse` spin in block allocation), positive focal lengths,
// pose translations within the world extent, and every colour frame with its depth frame.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/rgbd_sequence.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

namespace fs = std::filesystem;
using test::error_of;

std::string copy_of(const std::string& name) {
  const fs::path target = test::scratch_folder() / name;
  fs::copy(std::string(GLINT_TEST_DATA_DIR) + "/rgbd/" + name, target,
           fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  return target.string();
}

void expect_error(const std::string& folder, const std::string& file, const std::string& element,
                  const std::string& reason) {
  const Error error = error_of([&] { open_rgbd_sequence(folder); });
  EXPECT_EQ(error.file(), file);
  EXPECT_EQ(error.element(), element) << error.what();
  EXPECT_NE(error.reason().find(reason), std::string::npos) << error.what();
}

TEST(RgbdLimits, IntrinsicsOutsideTheImageAreRefused) {
  const std::string scenes = copy_of("7scenes");  // 16x12 frames
  const std::string k = scenes + "/camera-intrinsics.txt";
  test::write_text(k, "20 0 1e9\n0 20 5.5\n0 0 1\n");
  expect_error(scenes, k, "K.cx",
               "1000000000 is outside the allowed range [0, 16] for a 16x12 image");
  test::write_text(k, "-20 0 7.5\n0 20 5.5\n0 0 1\n");
  expect_error(scenes, k, "K.fx", "-20 is outside the allowed range (0, 16000]");

  const std::string glint = copy_of("glint");
  const std::string json = glint + "/intrinsics.json";
  test::write_text(json, R"({"width": 16, "height": 12, "fx": 20, "fy": -20, "cx": 8, "cy": 6})");
  expect_error(glint, json, "fy", "outside the allowed range");
}

TEST(RgbdLimits, PoseTranslationsOutsideTheWorldAreRefused) {
  const std::string tum = copy_of("tum");
  test::write_text(tum + "/groundtruth.txt", "99.99 1e30 0 0 0 0 0 1\n");
  expect_error(tum, tum + "/groundtruth.txt", "line 1 (tx ty tz)",
               "coordinate 1e+30 is outside the world extent [-100000, 100000] m");

  const std::string scenes = copy_of("7scenes");
  const std::string pose = scenes + "/rgbd-frames/frame-000151.pose.txt";
  test::write_text(pose, "1 0 0 0\n0 1 0 -2e6\n0 0 1 0\n0 0 0 1\n");
  expect_error(scenes, pose, "translation", "world extent");
}

TEST(RgbdLimits, ColourFrameWithoutItsDepthFrameIsAnError) {
  const std::string scenes = copy_of("7scenes");
  const std::string depth = scenes + "/rgbd-frames/frame-000151.depth.png";
  fs::remove(depth);
  expect_error(scenes, depth, "", "the depth image of frame-000151.color.png is missing");
}

}  // namespace
}  // namespace glint::io
