#pragma once
// FusionPipeline: the per-frame loop of real-time reconstruction (thesis §2.1; paper 1 §3.3):
// pose estimation (ICP against the model, or the dataset's ground truth), TSDF integration, and
// the model ray cast that the next frame is tracked against. Stage durations are recorded as
// "track", "integrate" and "raycast".
#include <memory>
#include <optional>

#include "core/camera.h"
#include "core/timer.h"
#include "fusion/cuda_integrator.h"
#include "fusion/icp_tracker.h"
#include "fusion/integrate.h"
#include "fusion/raycast.h"
#include "fusion/tsdf_volume.h"
#include "io/rgbd_sequence.h"

namespace glint::fusion {

// Where TSDF integration runs: the CPU, a CUDA GPU (CudaIntegrator: a GLINT_WITH_CUDA build and
// a GPU, else an error), or the GPU where there is one.
enum class IntegrationDevice { cpu, cuda, automatic };

struct FusionParams {
  VolumeParams volume;
  TrackingParams tracking;
  // Use each frame's ground-truth pose instead of tracking (frames without one are errors).
  bool use_ground_truth_poses = false;
  IntegrationDevice device = IntegrationDevice::cpu;
};

struct FrameResult {
  Pose camera_to_world = Pose::Identity();
  bool integrated = false;                 // false when tracking was lost (the frame is skipped)
  std::optional<TrackingResult> tracking;  // absent with ground-truth poses and for frame 0
  std::size_t visible_blocks = 0;
};

class FusionPipeline {
 public:
  // Throws glint::Error when params.device is cuda and CUDA is not available.
  FusionPipeline(const Intrinsics& intrinsics, const FusionParams& params);

  // Fuses one frame. The first frame is placed at its ground-truth pose when it has one, else at
  // the identity; later frames start tracking from a constant-velocity prediction. Throws
  // glint::Error when the block pool runs out or a ground-truth pose is missing.
  FrameResult process(const io::RgbdFrame& frame);

  const TsdfVolume& volume() const { return volume_; }
  // Where integration runs: "cpu" or "cuda".
  const char* integration_device() const { return gpu_ ? "cuda" : "cpu"; }
  const StageTimings& timings() const { return timings_; }

 private:
  Pose predict_pose() const;
  Intrinsics model_intrinsics() const;  // of the ray-cast model tracking aligns to

  Intrinsics intrinsics_;
  FusionParams params_;
  TsdfVolume volume_;
  std::unique_ptr<CudaIntegrator> gpu_;  // after volume_: unpins its pools before they go
  VisibleBlocks visible_;
  StageTimings timings_;
  SurfaceView model_;
  std::vector<Pose> poses_;
};

}  // namespace glint::fusion
