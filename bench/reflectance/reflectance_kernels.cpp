// The reflectance pipeline's per-element kernels (Google Benchmark): one HemiCNN estimate (25
// hemi-images -> Ward parameters, plain C++), one HemiImage, one observation insertion into a
// full voxel (m = 30), one voxel's albedo refinement (30 observations, 3 lights), and the
// per-frame depth segmentation of a 256x212 depth image (the pipeline's halved 512x424 frame).
//   reflectance_kernels [--benchmark_out=FILE.json --benchmark_out_format=json]
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include "core/resources.h"
#include "reflectance/albedo_refinement.h"
#include "reflectance/depth_segmentation.h"
#include "reflectance/hemi_image.h"
#include "reflectance/hemicnn.h"
#include "reflectance/observation.h"

namespace {

using namespace glint;
using namespace glint::reflectance;

// 30 observations over the upper hemisphere of +z with random colours.
std::vector<Observation> random_observations(int count, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<Observation> observations;
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector3f d(uniform(random) * 2 - 1, uniform(random) * 2 - 1,
                            uniform(random) + 0.05f);
    const Eigen::Vector3f colour(uniform(random), uniform(random), uniform(random));
    observations.emplace_back(colour, d.normalized(), std::uint32_t(k));
  }
  return observations;
}

HemiCnn shipped_or_default_model() {
  const std::filesystem::path path = models_directory() / "hemicnn.json";
  return std::filesystem::exists(path) ? HemiCnn::load(path) : HemiCnn();
}

void HemiCnnEstimate(benchmark::State& state) {
  const HemiCnn network = shipped_or_default_model();
  std::vector<float> images(25 * network.image_floats());
  const auto observations = random_observations(30, 1);
  for (int k = 0; k < 25; ++k)
    make_hemi_image(observations.data(), 30, Eigen::Vector3f::UnitZ(), HemiImageParams{},
                    images.data() + k * network.image_floats());
  HemiCnnScratch scratch;
  for (auto _ : state) benchmark::DoNotOptimize(network.predict(images.data(), 25, scratch));
  state.counters["parameters"] = double(network.parameter_count());
}
BENCHMARK(HemiCnnEstimate)->Unit(benchmark::kMicrosecond);

void HemiImage(benchmark::State& state) {
  const auto observations = random_observations(30, 2);
  std::vector<float> image(3 * 15 * 15);
  for (auto _ : state) {
    make_hemi_image(observations.data(), 30, Eigen::Vector3f::UnitZ(), HemiImageParams{},
                    image.data());
    benchmark::DoNotOptimize(image.data());
  }
}
BENCHMARK(HemiImage)->Unit(benchmark::kMicrosecond);

// The insertion kernel of argument `arg` (InsertionKernel: 0 scalar, 1 AVX2, 2 AVX-512); false,
// with the benchmark skipped, where this CPU cannot run it.
bool with_kernel(benchmark::State& state, int arg, InsertionKernel& kernel) {
  kernel = InsertionKernel(state.range(arg));
  for (const InsertionKernel supported : supported_insertion_kernels())
    if (supported == kernel) return true;
  state.SkipWithError("this CPU has no such instruction set");
  return false;
}

// Directions along a smooth camera path (each close to the one before, as in a video), the
// pipeline's usual case: about 0.6 degrees per frame.
std::vector<Observation> along_path(std::vector<Observation> observations) {
  for (std::size_t k = 0; k < observations.size(); ++k) {
    const float t = 0.01f * float(k);
    observations[k] = Observation(
        observations[k].colour(),
        Eigen::Vector3f(0.6f * std::cos(t), 0.6f * std::sin(1.3f * t), 0.8f).normalized(),
        observations[k].frame());
  }
  return observations;
}

// One voxel's observation slots and their nearest-observation entries.
struct VoxelSlots {
  explicit VoxelSlots(int capacity) : slots(capacity), similarity(capacity), nearest(capacity) {}
  int insert(InsertionKernel kernel, int count, const Observation& added) {
    return insert_observation(kernel, slots.data(), {similarity.data(), nearest.data()}, count,
                              int(slots.size()), added);
  }
  std::vector<Observation> slots;
  std::vector<float> similarity;
  std::vector<std::uint8_t> nearest;
};

// Arg 0: 0 = each new direction drawn at random over the hemisphere; 1 = along a camera path:
// the dropped observation is then mostly the newest stored one. Both cycle through 64 voxels so
// that the branch predictor cannot learn one voxel's comparisons. Arg 1: the kernel.
void InsertIntoFullVoxel(benchmark::State& state) {
  InsertionKernel kernel;
  if (!with_kernel(state, 1, kernel)) return;
  constexpr int kVoxels = 64;
  std::vector<VoxelSlots> voxels(kVoxels, VoxelSlots(30));
  for (int v = 0; v < kVoxels; ++v) {
    int count = 0;
    for (const Observation& o : random_observations(30, 3 + v))
      count = voxels[v].insert(kernel, count, o);
  }
  std::vector<Observation> incoming = random_observations(1024, 4);
  if (state.range(0) == 1) incoming = along_path(incoming);
  std::size_t next = 0;
  for (auto _ : state) {
    const int v = int(next % kVoxels);
    const Observation& next_seen = incoming[(next / kVoxels) % incoming.size()];
    const Observation added(next_seen.colour(), next_seen.direction(), std::uint32_t(100 + next));
    ++next;
    benchmark::DoNotOptimize(voxels[v].insert(kernel, 30, added));
  }
}
BENCHMARK(InsertIntoFullVoxel)->ArgsProduct({{0, 1}, {0, 1, 2}})->Unit(benchmark::kNanosecond);

// A voxel filled from empty to its 30 slots along a camera path, over and over: the insertions
// into voxels not yet full, about half of the pipeline's (cubes, 1 cm grid). Arg: the kernel.
void InsertIntoFillingVoxel(benchmark::State& state) {
  InsertionKernel kernel;
  if (!with_kernel(state, 0, kernel)) return;
  const std::vector<Observation> incoming = along_path(random_observations(30, 5));
  VoxelSlots voxel(30);
  for (auto _ : state) {
    int count = 0;
    for (const Observation& o : incoming) count = voxel.insert(kernel, count, o);
    benchmark::DoNotOptimize(count);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(incoming.size()));
}
BENCHMARK(InsertIntoFillingVoxel)->DenseRange(0, 2)->Unit(benchmark::kNanosecond);

// Arg: 0 = the paper's mean of the per-observation albedos, 1 = the median.
// Cycles through 256 voxels (64 KB of observations, in cache): with a single voxel the branch
// predictor learnt its median's comparisons, and the median measured 4-5x faster than in the
// pipeline.
void RefineAlbedo(benchmark::State& state) {
  constexpr int kVoxels = 256;
  std::vector<std::vector<Observation>> voxels;
  for (int v = 0; v < kVoxels; ++v) voxels.push_back(random_observations(30, 5 + v));
  std::vector<render::PointLight> lights(3);
  lights[0].position = {0.5, 2.0, 0.3};
  lights[1].position = {-1.5, 1.5, 1.0};
  lights[2].position = {0.0, 1.0, -2.0};
  const AlbedoAverage average = state.range(0) ? AlbedoAverage::median : AlbedoAverage::mean;
  int v = 0;
  for (auto _ : state) {
    const auto observed =
        observe_diffuse(voxels[v].data(), 30, Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitZ(),
                        lights, Eigen::Vector3f::Constant(0.1f), 0.1f, average);
    benchmark::DoNotOptimize(solve_albedo(*observed));
    v = (v + 1) % kVoxels;
  }
}
BENCHMARK(RefineAlbedo)->Arg(0)->Arg(1)->Unit(benchmark::kNanosecond);

// A floor 1.2 m below the camera and three spheres on it, seen 20 degrees downwards, with the
// depth quantised to millimetres: about the halved frames of the synthetic evaluation scenes
// (convex objects on a plane, depth 1-4 m, no depth noise).
ImageF sphere_scene_depth(const Intrinsics& k) {
  const Eigen::Vector3f down = Eigen::Vector3f(0, std::cos(0.35f), std::sin(0.35f));
  const float radii[3] = {0.3f, 0.4f, 0.5f};
  Eigen::Vector3f centres[3] = {{-0.6f, 0, 2.2f}, {0.3f, 0, 2.8f}, {1.2f, 0, 3.4f}};
  for (int s = 0; s < 3; ++s) centres[s] += (1.2f - radii[s] - centres[s].dot(down)) * down;
  ImageF depth(k.width, k.height, 1, 0.0f);
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      const Eigen::Vector3f ray = k.back_project(x, y, 1.0).cast<float>();
      float t = ray.dot(down) > 0 ? 1.2f / ray.dot(down) : INFINITY;  // the floor
      for (int s = 0; s < 3; ++s) {
        const float b = ray.dot(centres[s]), a = ray.squaredNorm();
        const float disc = b * b - a * (centres[s].squaredNorm() - radii[s] * radii[s]);
        if (disc > 0) t = std::min(t, (b - std::sqrt(disc)) / a);
      }
      if (!(t < 5.0f)) continue;
      depth.at(x, y, 0) = std::round(t * 1000.0f) / 1000.0f;
    }
  return depth;
}

void SegmentDepth(benchmark::State& state) {
  Intrinsics k;
  k.width = 256;
  k.height = 212;
  k.fx = k.fy = 182.5;
  k.cx = 127.75;
  k.cy = 105.75;
  const ImageF depth = sphere_scene_depth(k);
  DepthSegmenter segmenter;  // as the pipeline: one per stream, its buffers kept
  int segments = 0;
  for (auto _ : state) {
    const DepthSegmentation& result = segmenter.segment(depth, k);
    segments = result.segment_count;
    benchmark::DoNotOptimize(result.labels.plane(0));
  }
  state.counters["segments"] = segments;
}
BENCHMARK(SegmentDepth)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
