// ICP recovers a known rigid motion: the model is a TSDF of an analytic scene (a box corner
// with a sphere in front, well constrained in all six degrees of freedom) ray cast from the
// reference pose; the frame is the same scene's depth ray cast from the moved pose.
#include "fusion/icp_tracker.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "core/parallel.h"
#include "fusion_test_support.h"

namespace glint::fusion {
namespace {

// Free space is positive: inside the room (ceiling y = -0.4, back wall z = 2, side wall
// x = -0.6) and outside the sphere.
double scene_sdf(const Eigen::Vector3d& p) {
  const double sphere = (p - Eigen::Vector3d(0.2, 0.0, 1.3)).norm() - 0.25;
  return std::min({p.y() + 0.4, 2.0 - p.z(), p.x() + 0.6, sphere});
}

class IcpTracker : public ::testing::Test {
 protected:
  IcpTracker() : volume_(params()) { test::fill_analytic(volume_, scene_sdf, 2.2, 0.08); }
  static VolumeParams params() {
    VolumeParams p;
    p.voxel_size_m = 0.02;
    p.block_capacity = 20000;
    return p;
  }
  TsdfVolume volume_;
  const Intrinsics camera_{80, 60, 70.0, 70.0, 39.5, 29.5};
};

// A camera moved by `angle` about `axis` and by `translation` from the reference (identity).
Pose moved_pose(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& translation) {
  Pose moved = Pose::Identity();
  moved.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  moved.translation() = translation;
  return moved;
}

// Tracks the frame seen from `moved` (with `camera`) against the model ray cast from the
// reference (with `model_camera`) and checks the estimate is within `tolerance` (metres and
// radians) of `moved`.
TrackingResult expect_recovered(const TsdfVolume& volume, const Intrinsics& camera,
                                const Intrinsics& model_camera, const Pose& moved,
                                double tolerance) {
  const Pose reference = Pose::Identity();
  const SurfaceView model = raycast(volume, model_camera, reference);
  const SurfaceView frame = raycast(volume, camera, moved);
  const TrackingResult result =
      track_frame(frame.depth_m, camera, model, model_camera, reference, reference);
  EXPECT_EQ(result.status, TrackingStatus::tracked);
  const Pose error = result.camera_to_world.inverse() * moved;
  EXPECT_LT(error.translation().norm(), tolerance);
  EXPECT_LT(Eigen::AngleAxisd(error.rotation()).angle(), tolerance);
  return result;
}

TEST_F(IcpTracker, RecoversAKnownRigidMotion) {
  const Pose moved =
      moved_pose(0.03, Eigen::Vector3d(0.3, 1, 0.2), Eigen::Vector3d(0.02, -0.015, 0.03));
  EXPECT_LT(expect_recovered(volume_, camera_, camera_, moved, 0.002).rmse_m, 0.005);
}

// A frame of 83 x 61 pixels: the association's 8-pixel groups end in partial ones.
const Intrinsics kOddCamera{83, 61, 72.0, 72.0, 41.0, 30.0};
const Pose kOddMove =
    moved_pose(0.02, Eigen::Vector3d(-0.5, 1, 0.3), Eigen::Vector3d(-0.015, 0.01, 0.02));

TEST_F(IcpTracker, RecoversTheMotionAgainstAHalfResolutionModel) {
  expect_recovered(volume_, kOddCamera, kOddCamera.scaled(0.5), kOddMove, 0.003);
}

TEST_F(IcpTracker, TheEstimateDoesNotDependOnTheNumberOfThreads) {
  const Pose reference = Pose::Identity();
  const SurfaceView model = raycast(volume_, kOddCamera, reference);
  const SurfaceView frame = raycast(volume_, kOddCamera, kOddMove);
  const auto track = [&] {
    return track_frame(frame.depth_m, kOddCamera, model, kOddCamera, reference, reference);
  };
  const TrackingResult parallel = track();
  TrackingResult serial;
  {
    const auto one_thread = limit_threads(1);
    serial = track();
  }
  ASSERT_EQ(parallel.status, TrackingStatus::tracked);
  EXPECT_EQ(parallel.inliers, serial.inliers);
  EXPECT_EQ(parallel.rmse_m, serial.rmse_m);
  EXPECT_TRUE(parallel.camera_to_world.matrix() == serial.camera_to_world.matrix());
}

// A wall seen alone constrains only the distance to it and the tilts towards it: the estimate
// moves along its normal and keeps the prediction in the directions the wall leaves free (the
// translations along it, the roll about its normal), where a solution would be noise.
TEST_F(IcpTracker, DirectionsAWallLeavesFreeKeepThePrediction) {
  TsdfVolume wall(params());
  test::fill_analytic(
      wall, [](const Eigen::Vector3d& p) { return 2.0 - p.z(); }, 2.2, 0.08);
  const Pose reference = Pose::Identity();
  const SurfaceView model = raycast(wall, camera_, reference);
  const Pose moved = moved_pose(0, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.02, 0, 0.03));
  const TrackingResult result = track_frame(raycast(wall, camera_, moved).depth_m, camera_, model,
                                            camera_, reference, reference);
  ASSERT_EQ(result.status, TrackingStatus::tracked);
  EXPECT_NEAR(result.camera_to_world.translation().z(), 0.03, 0.002);
  EXPECT_NEAR(result.camera_to_world.translation().x(), 0, 1e-6);
  EXPECT_NEAR(result.camera_to_world.translation().y(), 0, 1e-6);
  EXPECT_LT(Eigen::AngleAxisd(result.camera_to_world.rotation()).angle(), 1e-3);
}

TEST_F(IcpTracker, EmptyFrameIsLostNotACrash) {
  const SurfaceView model = raycast(volume_, camera_, Pose::Identity());
  const TrackingResult result = track_frame(ImageF(80, 60, 1, 0.0f), camera_, model, camera_,
                                            Pose::Identity(), Pose::Identity());
  EXPECT_EQ(result.status, TrackingStatus::lost);
  EXPECT_TRUE(result.camera_to_world.isApprox(Pose::Identity()));
}

}  // namespace
}  // namespace glint::fusion
