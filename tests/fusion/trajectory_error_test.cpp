#include "fusion/trajectory_error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/error.h"

namespace glint::fusion {
namespace {

std::vector<Pose> circle_trajectory() {
  std::vector<Pose> poses;
  for (int i = 0; i < 20; ++i) {
    Pose pose = Pose::Identity();
    pose.translation() = Eigen::Vector3d(std::cos(0.3 * i), std::sin(0.3 * i), 0.05 * i);
    poses.push_back(pose);
  }
  return poses;
}

TEST(TrajectoryError, RigidlyMovedCopyHasZeroError) {
  const std::vector<Pose> truth = circle_trajectory();
  Pose offset = Pose::Identity();
  offset.linear() =
      Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  offset.translation() = Eigen::Vector3d(5, -2, 1);
  std::vector<Pose> estimated;
  for (const Pose& p : truth) estimated.push_back(offset * p);
  EXPECT_LT(absolute_trajectory_error(estimated, truth).rmse_m, 1e-9);
}

TEST(TrajectoryError, ConstantOffsetAlongOneAxisIsAlignedAwayButNoiseIsNot) {
  const std::vector<Pose> truth = circle_trajectory();
  std::vector<Pose> estimated = truth;
  // Alternating +-1 cm in z cannot be aligned away: RMSE 1 cm.
  for (std::size_t i = 0; i < estimated.size(); ++i)
    estimated[i].translation().z() += (i % 2 ? 0.01 : -0.01);
  const TrajectoryError error = absolute_trajectory_error(estimated, truth);
  EXPECT_NEAR(error.rmse_m, 0.01, 1e-3);
  EXPECT_EQ(error.poses, truth.size());
}

TEST(TrajectoryError, TooFewOrMismatchedPosesAreErrors) {
  const std::vector<Pose> truth = circle_trajectory();
  EXPECT_THROW(absolute_trajectory_error({truth[0], truth[1]}, {truth[0], truth[1]}), Error);
  EXPECT_THROW(absolute_trajectory_error(truth, {truth.begin(), truth.end() - 1}), Error);
}

}  // namespace
}  // namespace glint::fusion
