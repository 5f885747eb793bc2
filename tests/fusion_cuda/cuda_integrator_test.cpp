// CUDA integration (fusion/cuda_integrator.h) against the CPU's integrate_blocks() on the same
// frames. A separate executable, linking only glint_fusion, so that it can be carried to a GPU
// machine that lacks glint's other dependencies; without a GPU only the error test runs.
#include "fusion/cuda_integrator.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>

#include "core/error.h"
#include "core/parallel.h"

namespace glint::fusion {
namespace {

const Intrinsics kCamera{160, 120, 120.0, 120.0, 79.5, 59.5};

VolumeParams small_params(bool colour, int far_every) {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.truncation_m = 0.03;
  params.truncation_per_depth = 0.01;
  params.block_capacity = 1 << 14;
  params.colour = colour;
  params.far_fusion_every = far_every;
  params.far_voxel_pixels = 0.8;  // far field beyond 1.5 m
  return params;
}

// A ball of radius 0.3 m at (0, 0, 1.2) in front of a wall at z = 1.8 m, seen from a camera
// turned `yaw` radians about the ball's vertical axis; colour varies over the image.
struct Frame {
  ImageF depth, colour;
  Pose pose;
};

Frame ball_and_wall(double yaw) {
  const Eigen::Vector3d centre(0, 0, 1.2);
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.translation() = centre - pose.linear() * centre;  // orbit about the ball
  Frame frame{ImageF(kCamera.width, kCamera.height, 1), ImageF(kCamera.width, kCamera.height, 3),
              pose};
  const Eigen::Vector3d origin = pose.translation();
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      const Eigen::Vector3d ray_camera = kCamera.ray(x, y);  // z = 1
      const Eigen::Vector3d ray = pose.linear() * ray_camera;
      double t = (1.8 - origin.z()) / ray.z();  // the wall
      const Eigen::Vector3d to_centre = centre - origin;
      const double a = ray.squaredNorm(), b = ray.dot(to_centre);
      const double discriminant = b * b - a * (to_centre.squaredNorm() - 0.09);
      if (discriminant > 0) t = std::min(t, (b - std::sqrt(discriminant)) / a);
      frame.depth.at(x, y, 0) = float(t);  // depth along the optical axis: ray_camera.z() = 1
      frame.colour.at(x, y, 0) = float(x) / kCamera.width;
      frame.colour.at(x, y, 1) = float(y) / kCamera.height;
      frame.colour.at(x, y, 2) = float(t / 2);
    }
  return frame;
}

// How far a GPU-fused volume is from the CPU-fused one, block by block (pool indices may
// differ: allocation runs in parallel).
struct Agreement {
  long observed = 0;   // voxels with a weight in the CPU volume
  long differing = 0;  // of all voxels: weight differs, or distance / colour by more than 1e-5
  double worst_sdf = 0;
  long fusion_counts_differing = 0;
};

Agreement compare(const TsdfVolume& cpu, const TsdfVolume& gpu) {
  Agreement agreement;
  EXPECT_EQ(cpu.block_count(), gpu.block_count());
  for (std::size_t b = 0; b < cpu.block_count(); ++b) {
    const int block = int(b);
    const int other = gpu.hash().find(cpu.hash().block(block));
    if (other < 0) {
      ADD_FAILURE() << "block missing on the GPU side";
      continue;
    }
    agreement.fusion_counts_differing += cpu.fusions(block) != gpu.fusions(other);
    for (int v = 0; v < kVoxelsPerBlock; ++v) {
      const double sdf = std::abs(cpu.sdf_m(block)[v] - gpu.sdf_m(other)[v]);
      agreement.worst_sdf = std::max(agreement.worst_sdf, sdf);
      bool differs = cpu.weight(block)[v] != gpu.weight(other)[v] || sdf > 1e-5;
      if (cpu.has_colour())
        differs = differs || std::abs(cpu.red(block)[v] - gpu.red(other)[v]) > 1e-5 ||
                  std::abs(cpu.green(block)[v] - gpu.green(other)[v]) > 1e-5 ||
                  std::abs(cpu.blue(block)[v] - gpu.blue(other)[v]) > 1e-5;
      agreement.observed += cpu.weight(block)[v] > 0;
      agreement.differing += differs;
    }
  }
  return agreement;
}

// Fuses `frames` into a CPU volume and, through a CudaIntegrator, into a second one; the first
// `cpu_first` frames go into both on the CPU before the integrator is made.
void expect_same_fusion(const VolumeParams& params, int frames, int cpu_first) {
  // One thread: blocks then get the same pool indices in both volumes, and the far field's
  // schedule, staggered by pool index, is the same.
  const auto one_thread = limit_threads(1);
  TsdfVolume cpu(params), gpu(params);
  VisibleBlocks cpu_visible, gpu_visible;
  std::unique_ptr<CudaIntegrator> integrator;
  for (int i = 0; i < frames; ++i) {
    const Frame frame = ball_and_wall(0.15 * i);
    const ImageF colour = params.colour ? frame.colour : ImageF();
    integrate(cpu, frame.depth, colour, kCamera, frame.pose, cpu_visible);
    if (i < cpu_first) {
      integrate(gpu, frame.depth, colour, kCamera, frame.pose, gpu_visible);
      continue;
    }
    if (!integrator) integrator = std::make_unique<CudaIntegrator>(gpu);
    allocate_blocks(gpu, frame.depth, kCamera, frame.pose, gpu_visible);
    integrator->integrate_blocks(gpu, gpu_visible, frame.depth, colour, kCamera, frame.pose);
  }
  const Agreement agreement = compare(cpu, gpu);
  std::printf("%ld voxels observed, %ld differ (worst distance %.2g m), %ld fusion counts differ\n",
              agreement.observed, agreement.differing, agreement.worst_sdf,
              agreement.fusion_counts_differing);
  EXPECT_GT(agreement.observed, 20000);
  // Float rounding (fused multiply-adds) can move a voxel's projection across a pixel border.
  EXPECT_LE(agreement.differing, agreement.observed / 1000);
  EXPECT_EQ(agreement.fusion_counts_differing, 0);
}

TEST(CudaIntegrator, WithoutAGpuItIsAClearError) {
  if (CudaIntegrator::available()) GTEST_SKIP() << "a GPU is present";
  TsdfVolume volume(small_params(true, 1));
  try {
    CudaIntegrator integrator(volume);
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_EQ(error.file(), "CUDA");
    EXPECT_FALSE(error.reason().empty());
  }
}

TEST(CudaIntegrator, FusesAsTheCpuDoesWithColour) {
  if (!CudaIntegrator::available()) GTEST_SKIP() << "no GPU";
  expect_same_fusion(small_params(true, 1), 5, 0);
}

TEST(CudaIntegrator, FollowsTheFarFieldScheduleWithoutColour) {
  if (!CudaIntegrator::available()) GTEST_SKIP() << "no GPU";
  expect_same_fusion(small_params(false, 2), 5, 0);
}

TEST(CudaIntegrator, TakesOverAVolumeTheCpuStarted) {
  if (!CudaIntegrator::available()) GTEST_SKIP() << "no GPU";
  expect_same_fusion(small_params(true, 2), 5, 2);
}

TEST(CudaIntegrator, RefusesBadInput) {
  if (!CudaIntegrator::available()) GTEST_SKIP() << "no GPU";
  TsdfVolume volume(small_params(false, 1)), other(small_params(false, 1));
  CudaIntegrator integrator(volume);
  VisibleBlocks visible;
  const Frame frame = ball_and_wall(0);
  allocate_blocks(volume, frame.depth, kCamera, frame.pose, visible);
  EXPECT_THROW(integrator.integrate_blocks(volume, visible, ImageF(10, 10, 1), ImageF(), kCamera,
                                           frame.pose),
               Error);
  EXPECT_THROW(
      integrator.integrate_blocks(volume, visible, frame.depth, frame.colour, kCamera, frame.pose),
      Error)
      << "colour into a volume that keeps none";
  EXPECT_THROW(
      integrator.integrate_blocks(other, visible, frame.depth, ImageF(), kCamera, frame.pose),
      Error)
      << "not the integrator's volume";
}

}  // namespace
}  // namespace glint::fusion
