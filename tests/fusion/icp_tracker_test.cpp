// ICP recovers a known rigid motion: the model is a TSDF of an analytic scene (a box corner
// with a sphere in front, well constrained in all six degrees of freedom) ray cast from the
// reference pose; the frame is the same scene's depth ray cast from the moved pose.
#include "fusion/icp_tracker.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>

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

TEST_F(IcpTracker, RecoversAKnownRigidMotion) {
  const Pose reference = Pose::Identity();
  Pose moved = Pose::Identity();
  moved.linear() =
      Eigen::AngleAxisd(0.03, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  moved.translation() = Eigen::Vector3d(0.02, -0.015, 0.03);

  const SurfaceView model = raycast(volume_, camera_, reference);
  const SurfaceView frame = raycast(volume_, camera_, moved);
  const TrackingResult result =
      track_frame(frame.depth_m, camera_, model, camera_, reference, reference);
  ASSERT_EQ(result.status, TrackingStatus::tracked);
  const Pose error = result.camera_to_world.inverse() * moved;
  EXPECT_LT(error.translation().norm(), 0.002);
  EXPECT_LT(Eigen::AngleAxisd(error.rotation()).angle(), 0.002);
  EXPECT_LT(result.rmse_m, 0.005);
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
