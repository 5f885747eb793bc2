#pragma once
// Camera tracking by projective point-to-plane ICP against the ray-cast model (KinectFusion,
// Newcombe et al. 2011 §3.5; thesis §2.1 "pose estimation"). The new frame's depth is
// bilateral-filtered and reduced to a coarse-to-fine pyramid; at each level, each frame point is
// moved by the current pose estimate, projected into the model view (projective data
// association) and paired with the model point there; pairs farther apart than
// max_distance_m or with normals more than max_normal_angle_deg apart are rejected. Each
// iteration solves the linearised 6x6 normal equations of sum_i (n_i . (T p_i - q_i))^2.
#include <array>

#include "core/camera.h"
#include "core/image.h"
#include "fusion/depth_maps.h"
#include "fusion/raycast.h"

namespace glint::fusion {

struct TrackingParams {
  // Iterations per pyramid level, finest level first (KinectFusion: 10, 5, 4; these reach the
  // same ATE on 7-Scenes in half the time).
  std::array<int, 3> iterations{5, 4, 4};
  // A level stops iterating once an update moves the pose by less than this (the norm of the
  // twist: radians and metres; 1e-4 is 0.1 mm, or 0.3 mm at 3 m by rotation, under the depth
  // noise).
  double converged_twist = 1e-4;
  double max_distance_m = 0.10;
  double max_normal_angle_deg = 30;
  BilateralParams bilateral;
  // A solution with fewer inlier pairs than this fraction of the finest level's pixels counts as
  // lost.
  double min_inlier_fraction = 0.05;
  // Directions of the pose (eigenvectors of the normal equations) whose eigenvalue is under this
  // fraction of the largest are not updated: the pairs leave them free (a plane leaves the
  // translations along it free), and a solution there is noise.
  double min_constraint_ratio = 1e-5;
  // The model is ray cast at the frame's resolution halved this many times (FusionPipeline):
  // the frame's points associate with the nearest model pixel either way.
  int model_halvings = 0;
};

enum class TrackingStatus { tracked, lost };

struct TrackingResult {
  TrackingStatus status = TrackingStatus::lost;
  Pose camera_to_world = Pose::Identity();  // the estimate (the initial guess when lost)
  int inliers = 0;                          // finest level, last iteration
  double rmse_m = 0;                        // point-to-plane, inliers, finest level
};

// Aligns the frame (depth in metres, 0 = none; the frame's intrinsics) to `model`, ray cast with
// `model_intrinsics` from `model_camera_to_world`, starting from `initial_camera_to_world`.
TrackingResult track_frame(const ImageF& depth_m, const Intrinsics& intrinsics,
                           const SurfaceView& model, const Intrinsics& model_intrinsics,
                           const Pose& model_camera_to_world, const Pose& initial_camera_to_world,
                           const TrackingParams& params = {});

}  // namespace glint::fusion
