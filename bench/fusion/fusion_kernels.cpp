// TSDF fusion's per-frame kernels (Google Benchmark), on a synthetic 512x424 Kinect-v2-like frame
// (fx 365 px) of a room corner 1.5-4.5 m away, with the reflectance pipeline's volume (5 mm
// voxels, band 2 cm + 0.5 cm per metre, no colour): block allocation, and integration of the
// frame's visible blocks into a volume that has already fused it (steady state), items are
// voxels; and tracking's parts, items are pixels: the bilateral depth filter, the model's ray
// cast, the smoothing of its normals that re-renderings use, and tracking the frame seen from
// 1 cm and 0.6 degrees away against it. In a CUDA build
// (GLINT_WITH_CUDA), where a GPU is present, also the same integration on the GPU
// (fusion/cuda_integrator.h), the fused voxels written through to the host's pools.
//   fusion_kernels [--benchmark_repetitions=5 --benchmark_out=FILE.json
//   --benchmark_out_format=json]
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "fusion/cuda_integrator.h"
#include "fusion/depth_maps.h"
#include "fusion/icp_tracker.h"
#include "fusion/integrate.h"
#include "reflectance/reflectance_volume.h"

namespace {

using namespace glint;
using namespace glint::fusion;

const Intrinsics kKinect{512, 424, 365.0, 365.0, 255.5, 211.5};

// Depth of three walls meeting in a corner in front of the camera, 1.5 m at the nearest.
ImageF corner_depth() {
  ImageF depth(kKinect.width, kKinect.height, 1);
  const Eigen::Vector3d corner(0.3, 0.2, 4.5);
  const Eigen::Vector3d normals[3] = {Eigen::Vector3d(1, 0, -0.3).normalized(),
                                      Eigen::Vector3d(-0.8, 0, -0.5).normalized(),
                                      Eigen::Vector3d(0, -1, -0.2).normalized()};
  for (int y = 0; y < kKinect.height; ++y)
    for (int x = 0; x < kKinect.width; ++x) {
      const Eigen::Vector3d ray = kKinect.ray(x, y);
      double nearest = 0;
      for (const Eigen::Vector3d& n : normals) {  // the first wall the ray meets
        const double t = n.dot(corner) / n.dot(ray);
        if (t > 0 && (nearest == 0 || t < nearest)) nearest = t;
      }
      depth.at(x, y, 0) = float(std::clamp(nearest * ray.z(), 1.5, 4.5));
    }
  return depth;
}

void AllocateBlocks(benchmark::State& state) {
  TsdfVolume volume(reflectance::reflectance_volume_params());
  const ImageF depth = corner_depth();
  VisibleBlocks visible;
  for (auto _ : state) allocate_blocks(volume, depth, kKinect, Pose::Identity(), visible);
  state.counters["blocks"] = double(visible.indices.size());
}
BENCHMARK(AllocateBlocks)->Unit(benchmark::kMillisecond)->UseRealTime();

void IntegrateBlocks(benchmark::State& state) {
  TsdfVolume volume(reflectance::reflectance_volume_params());
  const ImageF depth = corner_depth();
  VisibleBlocks visible;
  integrate(volume, depth, ImageF(), kKinect, Pose::Identity(), visible);
  for (auto _ : state)
    integrate_blocks(volume, visible, depth, ImageF(), kKinect, Pose::Identity());
  state.counters["blocks"] = double(visible.indices.size());
  state.SetItemsProcessed(state.iterations() * std::int64_t(visible.indices.size()) *
                          kVoxelsPerBlock);
}
BENCHMARK(IntegrateBlocks)->Unit(benchmark::kMillisecond)->UseRealTime();

void BilateralFilterDepth(benchmark::State& state) {
  const ImageF depth = corner_depth();
  for (auto _ : state) benchmark::DoNotOptimize(bilateral_filter_depth(depth));
  state.SetItemsProcessed(state.iterations() * std::int64_t(depth.pixel_count()));
}
BENCHMARK(BilateralFilterDepth)->Unit(benchmark::kMillisecond)->UseRealTime();

// Fuses the corner frame from the identity pose into `volume`.
void fuse_corner(TsdfVolume& volume) {
  VisibleBlocks visible;
  integrate(volume, corner_depth(), ImageF(), kKinect, Pose::Identity(), visible);
}

void RaycastModel(benchmark::State& state) {
  TsdfVolume volume(reflectance::reflectance_volume_params());
  fuse_corner(volume);
  for (auto _ : state) benchmark::DoNotOptimize(raycast(volume, kKinect, Pose::Identity()));
  state.SetItemsProcessed(state.iterations() * std::int64_t(kKinect.width) * kKinect.height);
}
BENCHMARK(RaycastModel)->Unit(benchmark::kMillisecond)->UseRealTime();

// The edge-aware smoothing of a re-rendering's normals, 2 cm (the reconstruct default).
void SmoothNormals(benchmark::State& state) {
  TsdfVolume volume(reflectance::reflectance_volume_params());
  fuse_corner(volume);
  const SurfaceView view = raycast(volume, kKinect, Pose::Identity());
  for (auto _ : state)
    benchmark::DoNotOptimize(
        smooth_normals(view.points_m, view.normals, view.depth_m, kKinect, 0.02f));
  state.SetItemsProcessed(state.iterations() * std::int64_t(kKinect.width) * kKinect.height);
}
BENCHMARK(SmoothNormals)->Unit(benchmark::kMillisecond)->UseRealTime();

void TrackFrame(benchmark::State& state) {
  TsdfVolume volume(reflectance::reflectance_volume_params());
  fuse_corner(volume);
  const SurfaceView model = raycast(volume, kKinect, Pose::Identity());
  Pose moved = Pose::Identity();
  moved.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.2, 1, 0.1).normalized()).matrix();
  moved.translation() = Eigen::Vector3d(0.01, -0.005, 0.005);
  const ImageF frame = raycast(volume, kKinect, moved).depth_m;
  TrackingResult result;
  for (auto _ : state)
    result = track_frame(frame, kKinect, model, kKinect, Pose::Identity(), Pose::Identity());
  if (result.status != TrackingStatus::tracked) state.SkipWithError("lost");
  state.SetItemsProcessed(state.iterations() * std::int64_t(frame.pixel_count()));
}
BENCHMARK(TrackFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

#if defined(GLINT_WITH_CUDA)
// The same on the GPU: depth upload, kernel, and the fused voxels written through to the host.
void CudaIntegrateBlocks(benchmark::State& state) {
  if (!CudaIntegrator::available()) {
    state.SkipWithError("no GPU");
    return;
  }
  TsdfVolume volume(reflectance::reflectance_volume_params());
  const ImageF depth = corner_depth();
  VisibleBlocks visible;
  integrate(volume, depth, ImageF(), kKinect, Pose::Identity(), visible);
  CudaIntegrator integrator(volume);
  for (auto _ : state)
    integrator.integrate_blocks(volume, visible, depth, ImageF(), kKinect, Pose::Identity());
  state.counters["blocks"] = double(visible.indices.size());
  state.SetItemsProcessed(state.iterations() * std::int64_t(visible.indices.size()) *
                          kVoxelsPerBlock);
}
BENCHMARK(CudaIntegrateBlocks)->Unit(benchmark::kMillisecond)->UseRealTime();
#endif

}  // namespace

BENCHMARK_MAIN();
