#include "io/trajectory.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

TEST(Trajectory, TumRoundTripKeepsPosesAndTimestamps) {
  std::vector<StampedPose> poses(2);
  poses[0].timestamp = 1305031102.175304;
  poses[1].timestamp = 1305031102.211214;
  poses[1].pose.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  poses[1].pose.translation() = Eigen::Vector3d(1.25, -0.5, 3.0);
  const std::string path = testing::TempDir() + "traj.txt";
  write_tum_trajectory(path, poses);
  const auto back = read_tum_trajectory(path);
  ASSERT_EQ(back.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(back[i].timestamp, poses[i].timestamp, 1e-6);
    EXPECT_TRUE(back[i].pose.isApprox(poses[i].pose, 1e-7));
  }
}

TEST(Trajectory, TumQuaternionOrderIsXyzw) {
  const std::string path = testing::TempDir() + "quarter_turn.txt";
  std::ofstream(path) << "# comment\n\n0.5 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n";
  const auto poses = read_tum_trajectory(path);
  ASSERT_EQ(poses.size(), 1u);
  // A quarter turn about z maps x to y.
  EXPECT_TRUE(
      (poses[0].pose.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_EQ(poses[0].pose.translation(), Eigen::Vector3d(1, 2, 3));
}

TEST(Trajectory, MalformedLinesNameTheFileAndLine) {
  const std::string path = testing::TempDir() + "bad_traj.txt";
  std::ofstream(path) << "0 0 0 0 0 0 0 1\n1 0 0 nan 0 0 0 1\n";
  try {
    read_tum_trajectory(path);
    FAIL() << "expected glint::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.element(), "line 2");
  }
  std::ofstream(path) << "0 0 0 0 0 0 0 5\n";
  EXPECT_THROW(read_tum_trajectory(path), Error);
  std::ofstream(path) << "0 0 0\n";
  EXPECT_THROW(read_tum_trajectory(path), Error);
}

TEST(Intrinsics, JsonRoundTripAndValidation) {
  const std::string path = testing::TempDir() + "intrinsics.json";
  write_intrinsics_json(path, kinect_v2_intrinsics());
  const Intrinsics k = read_intrinsics_json(path);
  EXPECT_EQ(k.width, 512);
  EXPECT_EQ(k.height, 424);
  EXPECT_DOUBLE_EQ(k.fx, kinect_v2_intrinsics().fx);
  EXPECT_DOUBLE_EQ(k.cy, kinect_v2_intrinsics().cy);
  std::ofstream(path) << R"({"width": 512, "height": 424, "fx": 0, "fy": 1, "cx": 0, "cy": 0})";
  EXPECT_THROW(read_intrinsics_json(path), Error);
  std::ofstream(path) << R"({"width": 512})";
  EXPECT_THROW(read_intrinsics_json(path), Error);
}

TEST(Intrinsics, ProjectInvertsBackProject) {
  const Intrinsics k = kinect_v2_intrinsics();
  const Eigen::Vector3d p = k.back_project(100.25, 300.5, 2.5);
  EXPECT_NEAR(p.z(), 2.5, 1e-12);
  EXPECT_TRUE(k.project(p).isApprox(Eigen::Vector2d(100.25, 300.5), 1e-12));
  const Intrinsics half = k.scaled(0.5);
  EXPECT_EQ(half.width, 256);
  // The centre of the 2x2 block of pixels (0,0)-(1,1) is pixel (0,0) at half resolution.
  EXPECT_TRUE(half.project(p * 1.0).isApprox(
      (k.project(p) + Eigen::Vector2d(0.5, 0.5)) * 0.5 - Eigen::Vector2d(0.5, 0.5), 1e-12));
}

}  // namespace
}  // namespace glint::io
