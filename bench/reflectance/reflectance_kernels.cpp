// The reflectance pipeline's per-element kernels (Google Benchmark): one HemiCNN estimate (25
// hemi-images -> Ward parameters, plain C++), one HemiImage, one observation insertion into a
// full voxel (m = 30), one voxel's albedo refinement (30 observations, 3 lights).
//   reflectance_kernels [--benchmark_out=FILE.json --benchmark_out_format=json]
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>
#include <vector>

#include "reflectance/albedo_refinement.h"
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
  std::vector<Observation> observations(count);
  for (int k = 0; k < count; ++k) {
    Eigen::Vector3f d(uniform(random) * 2 - 1, uniform(random) * 2 - 1, uniform(random) + 0.05f);
    observations[k].direction = d.normalized();
    observations[k].colour = Eigen::Vector3f(uniform(random), uniform(random), uniform(random));
    observations[k].frame = std::uint32_t(k);
  }
  return observations;
}

HemiCnn shipped_or_default_model() {
  const std::string path = std::string(GLINT_SOURCE_MODELS_DIR) + "/hemicnn.json";
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

void InsertIntoFullVoxel(benchmark::State& state) {
  const auto initial = random_observations(30, 3);
  std::vector<Observation> slots(30);
  std::vector<NearestObservation> nearest(30);
  int count = 0;
  for (const Observation& o : initial)
    count = insert_observation(slots.data(), nearest.data(), count, 30, o);
  const auto incoming = random_observations(1024, 4);
  std::size_t next = 0;
  for (auto _ : state) {
    Observation added = incoming[next++ % incoming.size()];
    added.frame = std::uint32_t(100 + next);
    benchmark::DoNotOptimize(insert_observation(slots.data(), nearest.data(), count, 30, added));
  }
}
BENCHMARK(InsertIntoFullVoxel)->Unit(benchmark::kNanosecond);

// Arg: 0 = the paper's mean of the per-observation albedos, 1 = the median.
void RefineAlbedo(benchmark::State& state) {
  const auto observations = random_observations(30, 5);
  std::vector<render::PointLight> lights(3);
  lights[0].position = {0.5, 2.0, 0.3};
  lights[1].position = {-1.5, 1.5, 1.0};
  lights[2].position = {0.0, 1.0, -2.0};
  const AlbedoAverage average = state.range(0) ? AlbedoAverage::median : AlbedoAverage::mean;
  for (auto _ : state)
    benchmark::DoNotOptimize(refine_albedo(observations.data(), 30, Eigen::Vector3f::Zero(),
                                           Eigen::Vector3f::UnitZ(), lights,
                                           Eigen::Vector3f::Constant(0.1f), 0.1f, average));
}
BENCHMARK(RefineAlbedo)->Arg(0)->Arg(1)->Unit(benchmark::kNanosecond);

}  // namespace

BENCHMARK_MAIN();
