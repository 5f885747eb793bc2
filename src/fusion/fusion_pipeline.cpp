#include "fusion/fusion_pipeline.h"

#include <string>

#include "core/error.h"
#include "fusion/depth_maps.h"

namespace glint::fusion {

FusionPipeline::FusionPipeline(const Intrinsics& intrinsics, const FusionParams& params)
    : intrinsics_(intrinsics), params_(params), volume_(params.volume) {
  if (params.tracking.model_halvings < 0 || params.tracking.model_halvings > 4)
    throw Error("tracking", "model_halvings",
                "must be in 0..4, got " + std::to_string(params.tracking.model_halvings));
  if (params.device == IntegrationDevice::cuda ||
      (params.device == IntegrationDevice::automatic && CudaIntegrator::available()))
    gpu_ = std::make_unique<CudaIntegrator>(volume_);
}

Pose FusionPipeline::predict_pose() const {
  if (poses_.size() < 2) return poses_.back();
  const Pose& last = poses_.back();
  return last * (poses_[poses_.size() - 2].inverse() * last);
}

Intrinsics FusionPipeline::model_intrinsics() const {
  return halved_intrinsics(intrinsics_, params_.tracking.model_halvings);
}

FrameResult FusionPipeline::process(const io::RgbdFrame& frame) {
  FrameResult result;
  if (params_.use_ground_truth_poses) {
    if (!frame.ground_truth)
      throw Error("frame " + std::to_string(frame.index), "",
                  "has no ground-truth pose (drop --gt-poses to track instead)");
    result.camera_to_world = *frame.ground_truth;
  } else if (poses_.empty()) {
    result.camera_to_world = frame.ground_truth.value_or(Pose::Identity());
  } else {
    Stopwatch watch;
    result.tracking = track_frame(frame.depth_m, intrinsics_, model_, model_intrinsics(),
                                  poses_.back(), predict_pose(), params_.tracking);
    timings_.add("track", watch.elapsed_ms());
    result.camera_to_world = result.tracking->status == TrackingStatus::tracked
                                 ? result.tracking->camera_to_world
                                 : poses_.back();
  }
  poses_.push_back(result.camera_to_world);

  if (!result.tracking || result.tracking->status == TrackingStatus::tracked) {
    Stopwatch watch;
    allocate_blocks(volume_, frame.depth_m, intrinsics_, result.camera_to_world, visible_);
    const double allocate_ms = watch.elapsed_ms();
    const ImageF no_colour;
    const ImageF& colour = volume_.has_colour() ? frame.colour : no_colour;
    if (gpu_)
      gpu_->integrate_blocks(volume_, visible_, frame.depth_m, colour, intrinsics_,
                             result.camera_to_world);
    else
      integrate_blocks(volume_, visible_, frame.depth_m, colour, intrinsics_,
                       result.camera_to_world);
    timings_.add("integrate", watch.elapsed_ms());
    timings_.add("allocate_blocks", allocate_ms);
    result.integrated = true;
    result.visible_blocks = visible_.indices.size();
  }
  if (!params_.use_ground_truth_poses) {
    Stopwatch watch;
    // The frame was just fused from this pose: its depth tells each ray where the surface is,
    // and where it has none, no ray is cast.
    ImageF halved;
    const ImageF& hint = halved_depth(frame.depth_m, params_.tracking.model_halvings,
                                      params_.tracking.bilateral.sigma_depth_m, halved);
    model_ = raycast(volume_, model_intrinsics(), result.camera_to_world,
                     {.depth_hint = &hint, .hinted_pixels_only = true});
    timings_.add("raycast", watch.elapsed_ms());
  }
  return result;
}

}  // namespace glint::fusion
