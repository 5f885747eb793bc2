// The pipeline on the tiny reader fixture (tests/data/rgbd/glint: a wall 1.0-1.15 m in front
// of a 16x12 camera): ground-truth poses give a wall mesh; tracking (also against a
// half-resolution model), a too-small block pool and bad parameters are handled without a crash.
#include "fusion/fusion_pipeline.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "fusion/marching_cubes.h"
#include "io/rgbd_sequence.h"

namespace glint::fusion {
namespace {

io::RgbdSequence fixture() {
  return io::open_rgbd_sequence(std::string(GLINT_TEST_DATA_DIR) + "/rgbd/glint");
}

FusionParams small_params(bool ground_truth) {
  FusionParams params;
  params.volume.voxel_size_m = 0.01;
  params.volume.block_capacity = 2000;
  params.volume.allocation_stride_px = 1;
  params.use_ground_truth_poses = ground_truth;
  return params;
}

TEST(FusionPipeline, GroundTruthPosesGiveTheWall) {
  const io::RgbdSequence sequence = fixture();
  FusionPipeline pipeline(sequence.intrinsics, small_params(true));
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const FrameResult result = pipeline.process(io::read_rgbd_frame(sequence, i));
    EXPECT_TRUE(result.integrated);
    EXPECT_GT(result.visible_blocks, 0u);
    EXPECT_NEAR(result.camera_to_world.translation().x(), 0.01 * i, 1e-9);
  }
  const TriangleMesh mesh = extract_mesh(pipeline.volume());
  ASSERT_GT(mesh.triangles.size(), 10u);
  for (const Eigen::Vector3f& v : mesh.vertices) {
    EXPECT_GT(v.z(), 0.98f);
    EXPECT_LT(v.z(), 1.2f);
  }
  EXPECT_GT(pipeline.timings().median_ms("integrate"), 0.0);
  EXPECT_EQ(pipeline.timings().to_json()["integrate"]["count"], 3);
}

TEST(FusionPipeline, TrackingRunsAndReportsEveryFrame) {
  const io::RgbdSequence sequence = fixture();
  FusionPipeline pipeline(sequence.intrinsics, small_params(false));
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const FrameResult result = pipeline.process(io::read_rgbd_frame(sequence, i));
    EXPECT_EQ(result.tracking.has_value(), i > 0);
    EXPECT_TRUE(result.camera_to_world.matrix().allFinite());
  }
  EXPECT_EQ(pipeline.timings().to_json()["raycast"]["count"], 3);
}

// The GPU path against the CPU one where there is a GPU; otherwise the device choice alone: cuda
// is a clear error, auto falls back to the CPU.
TEST(FusionPipeline, IntegrationDeviceChoice) {
  const io::RgbdSequence sequence = fixture();
  FusionParams params = small_params(true);
  params.device = IntegrationDevice::automatic;
  FusionPipeline automatic(sequence.intrinsics, params);
  params.device = IntegrationDevice::cuda;
  if (!CudaIntegrator::available()) {
    EXPECT_STREQ(automatic.integration_device(), "cpu");
    EXPECT_THROW(FusionPipeline(sequence.intrinsics, params), Error);
    return;
  }
  FusionPipeline gpu(sequence.intrinsics, params);
  params.device = IntegrationDevice::cpu;
  FusionPipeline cpu(sequence.intrinsics, params);
  EXPECT_STREQ(gpu.integration_device(), "cuda");
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const io::RgbdFrame frame = io::read_rgbd_frame(sequence, i);
    gpu.process(frame);
    cpu.process(frame);
  }
  ASSERT_EQ(gpu.volume().block_count(), cpu.volume().block_count());
  for (std::size_t b = 0; b < cpu.volume().block_count(); ++b) {
    const int other = gpu.volume().hash().find(cpu.volume().hash().block(int(b)));
    ASSERT_GE(other, 0);
    for (int v = 0; v < kVoxelsPerBlock; ++v) {
      EXPECT_EQ(gpu.volume().weight(other)[v], cpu.volume().weight(int(b))[v]);
      EXPECT_NEAR(gpu.volume().sdf_m(other)[v], cpu.volume().sdf_m(int(b))[v], 1e-5);
    }
  }
}

TEST(FusionPipeline, ExhaustedPoolAndMissingGroundTruthAreErrors) {
  const io::RgbdSequence sequence = fixture();
  FusionParams params = small_params(true);
  params.volume.block_capacity = 1;
  FusionPipeline tiny(sequence.intrinsics, params);
  EXPECT_THROW(tiny.process(io::read_rgbd_frame(sequence, 0)), Error);

  FusionPipeline pipeline(sequence.intrinsics, small_params(true));
  io::RgbdFrame frame = io::read_rgbd_frame(sequence, 0);
  frame.ground_truth.reset();
  EXPECT_THROW(pipeline.process(frame), Error);

  params = small_params(false);
  params.tracking.model_halvings = 5;
  EXPECT_THROW(FusionPipeline(sequence.intrinsics, params), Error);
}

// Tracking against a model ray cast at half the frame's resolution (the fixture's wall alone
// leaves three degrees of freedom open, so only the run itself is checked, as above).
TEST(FusionPipeline, TracksAgainstAHalfResolutionModel) {
  const io::RgbdSequence sequence = fixture();
  FusionParams params = small_params(false);
  params.tracking.model_halvings = 1;
  FusionPipeline pipeline(sequence.intrinsics, params);
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const FrameResult result = pipeline.process(io::read_rgbd_frame(sequence, i));
    EXPECT_EQ(result.tracking.has_value(), i > 0);
    EXPECT_TRUE(result.camera_to_world.matrix().allFinite());
  }
  EXPECT_EQ(pipeline.timings().to_json()["raycast"]["count"], 3);
}

}  // namespace
}  // namespace glint::fusion
