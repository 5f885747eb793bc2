// Camera paths: look-at poses, orbit and oscillation geometry, the light-capture path.
#include "render/trajectories.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace glint::render {
namespace {

const Intrinsics kCamera = kinect_v2_intrinsics();

Eigen::Vector2d project(const Pose& camera_to_world, const Eigen::Vector3d& world_point) {
  return kCamera.project(camera_to_world.inverse() * world_point);
}

TEST(LookAt, TargetProjectsToThePrincipalPoint) {
  const Eigen::Vector3d eye(3, 1.7, -2), target(0.2, 0.4, 0.5);
  const Pose pose = look_at(eye, target);
  EXPECT_NEAR((pose.linear().transpose() * pose.linear() - Eigen::Matrix3d::Identity()).norm(), 0,
              1e-12);
  EXPECT_NEAR(pose.linear().determinant(), 1, 1e-12);
  EXPECT_TRUE(pose.translation().isApprox(eye));
  const Eigen::Vector3d in_camera = pose.inverse() * target;
  EXPECT_GT(in_camera.z(), 0);
  const Eigen::Vector2d pixel = kCamera.project(in_camera);
  EXPECT_NEAR(pixel.x(), kCamera.cx, 1e-9);
  EXPECT_NEAR(pixel.y(), kCamera.cy, 1e-9);
}

TEST(LookAt, WorldUpIsUpInTheImageAndTheHorizonLevel) {
  const Pose pose = look_at({0, 1.5, 4}, {0, 0.5, 0});
  // Camera x (image right) is horizontal; a point above the target is higher in the image.
  EXPECT_NEAR(pose.linear().col(0).y(), 0, 1e-12);
  EXPECT_LT(project(pose, {0, 1.0, 0}).y(), kCamera.cy);
  // Looking along -z from +z, world +x appears on the right.
  EXPECT_GT(project(pose, {0.5, 0.5, 0}).x(), kCamera.cx);
}

TEST(LookAt, DegenerateInputsThrow) {
  EXPECT_THROW(look_at({1, 1, 1}, {1, 1, 1}), Error);
  EXPECT_THROW(look_at({0, 0, 0}, {0, 3, 0}), Error);
}

TEST(Orbit, RadiusHeightAndStepAreExact) {
  OrbitParams params;
  params.ring = {{1, 0, -2}, 3.5, 1.25, {1, 0.5, -2}};
  params.start_deg = 30;
  params.arc_deg = 360;
  params.frames = 36;
  const std::vector<Pose> poses = orbit_trajectory(params);
  ASSERT_EQ(poses.size(), 36u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector3d offset = poses[i].translation() - params.ring.centre;
    EXPECT_NEAR(std::hypot(offset.x(), offset.z()), 3.5, 1e-12);
    EXPECT_NEAR(offset.y(), 1.25, 1e-12);
    const double azimuth_deg = std::atan2(offset.x(), offset.z()) * 180 / M_PI;
    EXPECT_NEAR(std::remainder(azimuth_deg - (30 + 10.0 * i), 360), 0, 1e-9);
    const Eigen::Vector2d pixel = project(poses[i], params.ring.target);
    EXPECT_NEAR(pixel.x(), kCamera.cx, 1e-9);
    EXPECT_NEAR(pixel.y(), kCamera.cy, 1e-9);
  }
}

TEST(Oscillation, SwingsWithinTheAmplitudeAndLooksAtTheTarget) {
  OscillationParams params;
  params.ring = {{0, 0, 0}, 4, 1.5, {0, 0.6, 0}};
  params.centre_deg = 20;
  params.amplitude_deg = 45;
  params.periods = 2;
  params.height_amplitude_m = 0.3;
  params.frames = 200;
  const std::vector<Pose> poses = oscillation_trajectory(params);
  ASSERT_EQ(poses.size(), 200u);
  double lowest = 1e9, highest = -1e9;
  for (const Pose& pose : poses) {
    const Eigen::Vector3d eye = pose.translation();
    EXPECT_NEAR(std::hypot(eye.x(), eye.z()), 4, 1e-12);
    EXPECT_LE(std::abs(eye.y() - 1.5), 0.3 + 1e-12);
    const double azimuth_deg = std::atan2(eye.x(), eye.z()) * 180 / M_PI;
    lowest = std::min(lowest, azimuth_deg);
    highest = std::max(highest, azimuth_deg);
    EXPECT_NEAR(project(pose, params.ring.target).x(), kCamera.cx, 1e-9);
  }
  EXPECT_NEAR(lowest, 20 - 45, 0.1);
  EXPECT_NEAR(highest, 20 + 45, 0.1);
  EXPECT_NEAR(std::atan2(poses[0].translation().x(), poses[0].translation().z()) * 180 / M_PI, 20,
              1e-9);
}

TEST(Trajectories, NoFramesThrows) {
  OrbitParams orbit;
  orbit.frames = 0;
  EXPECT_THROW(orbit_trajectory(orbit), Error);
  OscillationParams oscillation;
  oscillation.frames = -1;
  EXPECT_THROW(oscillation_trajectory(oscillation), Error);
}

TEST(LightCapture, EachBlockKeepsItsLightInView) {
  const std::vector<Eigen::Vector3d> lights = {{-1, 2.6, -0.8}, {1.2, 2.6, -1.6}, {0, 2.4, 0.8}};
  LightCaptureParams params;
  params.frames = 61;
  const std::vector<Pose> poses = light_capture_trajectory(lights, params);
  ASSERT_EQ(poses.size(), 61u);
  std::vector<int> frames_per_light(lights.size(), 0);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::size_t light = i * lights.size() / poses.size();
    ++frames_per_light[light];
    const Eigen::Vector3d in_camera = poses[i].inverse() * lights[light];
    ASSERT_GT(in_camera.z(), 0);
    const Eigen::Vector2d pixel = kCamera.project(in_camera);
    EXPECT_GT(pixel.x(), 0.1 * kCamera.width) << "frame " << i;
    EXPECT_LT(pixel.x(), 0.9 * kCamera.width) << "frame " << i;
    EXPECT_GT(pixel.y(), 0.1 * kCamera.height) << "frame " << i;
    EXPECT_LT(pixel.y(), 0.9 * kCamera.height) << "frame " << i;
    // Off-centre by the wobble: the light moves across the image.
    EXPECT_GT((pixel - Eigen::Vector2d(kCamera.cx, kCamera.cy)).norm(), 20) << "frame " << i;
    // The camera looks up at the lights from below them.
    EXPECT_LT(poses[i].translation().y(), lights[light].y());
  }
  for (int count : frames_per_light) EXPECT_GE(count, 20);
}

TEST(LightCapture, NeedsLightsAndAFramePerLight) {
  LightCaptureParams params;
  EXPECT_THROW(light_capture_trajectory({}, params), Error);
  params.frames = 1;
  EXPECT_THROW(light_capture_trajectory({{0, 2, 0}, {1, 2, 0}}, params), Error);
}

}  // namespace
}  // namespace glint::render
