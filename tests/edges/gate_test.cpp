// The gates of a BoundED model file (edges/model.h): the statistics they read, the file's round
// trip (its errors: model_test.cpp), and the choice of network per cloud.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include "core/error.h"
#include "edges/classifier.h"
#include "edges/model.h"

namespace glint::edges {
namespace {

// A network that calls every point `label` (zero weights, the output bias decides).
Model constant_model(int label, int classes = 3) {
  ModelConfig config;
  config.classes = classes;
  Model model(config);
  model.layers.back().bias.assign(classes, 0.0f);
  model.layers.back().bias[label] = 5.0f;
  return model;
}

// A 60 x 60 grid of unit spacing in the plane z = 0, displaced along z by Gaussian noise of
// `sigma` spacings.
PointCloud noisy_plane(float sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma);
  PointCloud cloud;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 60; ++x) cloud.push_back(float(x), float(y), sigma > 0 ? noise(rng) : 0.0f);
  return cloud;
}

std::vector<float> statistics(const PointCloud& cloud) {
  const FeatureMatrix features = compute_features(cloud);
  std::vector<float> values(features.points);
  for (std::size_t i = 0; i < features.points; ++i)
    values[i] = noise_statistic(features.row(i), features.scales, features.per_scale);
  return values;
}

float median(std::vector<float> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

TEST(NoiseStatistic, IsZeroOnACleanPlaneAndGrowsWithTheNoise) {
  const std::vector<float> clean = statistics(noisy_plane(0.0f, 1));
  EXPECT_LT(*std::max_element(clean.begin(), clean.end()), 1e-3f);
  float previous = 0.0f;
  for (const float sigma : {0.1f, 0.25f, 0.5f, 1.0f}) {
    const float level = median(statistics(noisy_plane(sigma, 2)));
    EXPECT_GT(level, previous) << "noise " << sigma;
    previous = level;
  }
  // On a unit grid the median is about 0.55 sigma (measured: 0.56 at 0.1, 0.54 at 0.5, 0.46 at
  // 1 spacing, where the neighbourhood itself thickens); a test of scale, not of the constant.
  const float at_quarter_spacing = median(statistics(noisy_plane(0.25f, 3)));
  EXPECT_GT(at_quarter_spacing, 0.10f);
  EXPECT_LT(at_quarter_spacing, 0.20f);
}

// Every point answered by one network of constant_model(1) gated with constant_model(0).
void expect_answered_by(const Classification& result, bool gate_network, std::size_t points) {
  ASSERT_EQ(result.gates.size(), 1u);
  EXPECT_EQ(result.gates[0].gate_network_answered, gate_network);
  const std::uint8_t label = gate_network ? 0 : 1;
  EXPECT_EQ(std::count(result.labels.begin(), result.labels.end(), label), std::ptrdiff_t(points));
}

TEST(NoiseGate, ChoosesTheLowNoiseNetworkOnlyForAQuietCloud) {
  const Model gated = constant_model(1).with_gate(GateKind::noise, constant_model(0), 0.1f);
  const PointCloud clean = noisy_plane(0.0f, 1), noisy = noisy_plane(0.5f, 4);

  const Classification quiet = classify(clean, gated);
  expect_answered_by(quiet, true, clean.size());
  EXPECT_EQ(quiet.gates[0].statistic, 1.0);  // every point quiet
  EXPECT_EQ(quiet.gates[0].kind, GateKind::noise);
  EXPECT_EQ(quiet.gates[0].threshold, 0.1f);
  EXPECT_EQ(network_name(quiet.gates), "low-noise");
  const Classification loud = classify(noisy, gated);
  expect_answered_by(loud, false, noisy.size());
  EXPECT_LT(loud.gates[0].statistic, 0.5);
  EXPECT_EQ(network_name(loud.gates), "noisy");
  // The gate chooses before the features: no feature matrix serves a gated model.
  EXPECT_THROW(classify_features(compute_features(clean), gated), Error);
}

// A noise tally of `quiet` values below the threshold 0.1 and `loud` above it.
GateTally noise_tally(int quiet, int loud) {
  GateTally tally(GateKind::noise, 0.1f);
  for (int i = 0; i < quiet; ++i) tally.add(0.05f);
  for (int i = 0; i < loud; ++i) tally.add(0.5f);
  return tally;
}

TEST(NoiseGate, MajorityRuleIsStrict) {
  EXPECT_TRUE(noise_tally(51, 49).gate_network_answers());
  EXPECT_FALSE(noise_tally(50, 50).gate_network_answers());
  EXPECT_FALSE(noise_tally(0, 0).gate_network_answers());
  EXPECT_DOUBLE_EQ(noise_tally(51, 49).statistic(), 0.51);
}

TEST(NoiseGate, RejectsNetworksThatDoNotFitAndBadThresholds) {
  EXPECT_THROW(constant_model(1).with_gate(GateKind::noise, constant_model(1, 2), 0.1f), Error);
  ModelConfig other_scales;
  other_scales.scales = {64, 32, 16, 8};
  EXPECT_THROW(constant_model(1).with_gate(GateKind::sampling, Model(other_scales), 0.1f), Error);
  ModelConfig with_gap;
  with_gap.angular_gap = true;
  EXPECT_THROW(constant_model(1).with_gate(GateKind::sampling, Model(with_gap), 0.1f), Error);
  ModelConfig wider;
  wider.hidden = 32;
  EXPECT_THROW(constant_model(1).with_gate(GateKind::sampling, Model(wider), 0.1f), Error);
  EXPECT_THROW(constant_model(1).with_gate(GateKind::noise, constant_model(0), 0.0f), Error);
  EXPECT_THROW(constant_model(1).with_gate(GateKind::sampling, constant_model(0), std::nanf("")),
               Error);
  const Model gated = constant_model(1).with_gate(GateKind::noise, constant_model(0), 0.1f);
  EXPECT_THROW(gated.with_gate(GateKind::noise, constant_model(0), 0.1f), Error);
}

// The noise statistic of every point as the gate reads it, the share of quiet points of a sample
// as of the whole cloud: half a clean plane, half a noisy one, side by side.
TEST(NoiseGate, ALargeCloudsSampleIsAsQuietAsTheWholeCloud) {
  PointCloud cloud;
  std::mt19937_64 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.5f);
  for (int y = 0; y < 150; ++y)
    for (int x = 0; x < 300; ++x) cloud.push_back(float(x), float(y), x < 150 ? 0.0f : noise(rng));
  ASSERT_GT(cloud.size(), kNoiseGatePoints);
  const Model gated = constant_model(1).with_gate(GateKind::noise, constant_model(0), 0.1f);
  std::vector<std::uint8_t> every(cloud.size(), gate_read_bit(GateKind::noise));
  std::vector<std::uint8_t> sample(cloud.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (gate_reads(GateKind::noise, i, cloud.size())) sample[i] = gate_read_bit(GateKind::noise);
  const GateTally whole = gate_tallies(cloud, gated, every)[0];
  const GateTally sampled = gate_tallies(cloud, gated, sample)[0];
  EXPECT_EQ(whole.points(), cloud.size());
  EXPECT_LT(sampled.points(), cloud.size());
  EXPECT_NEAR(whole.statistic(), 0.5, 0.05);
  EXPECT_NEAR(sampled.statistic(), whole.statistic(), 0.02);
  // The statistic is the features': the same values as noise_statistic of each row.
  const std::vector<float> rows = statistics(cloud);
  GateTally from_rows = gated.new_tally();
  for (const float value : rows) from_rows.add(value);
  EXPECT_EQ(from_rows.counts(), GateTally(whole).counts());
  // Masks that do not fit the cloud, and a model without a gate, are refused.
  EXPECT_THROW(gate_tallies(cloud, gated, std::vector<std::uint8_t>(10, 1)), Error);
  EXPECT_THROW(gate_tallies(cloud, constant_model(1), every), Error);
}

// A network with random weights, so that its answers depend on every input.
Model random_network(std::uint64_t seed, bool area_weights) {
  ModelConfig config;
  config.area_weights = area_weights;
  Model model(config);
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> weight(0.0f, 0.5f);
  for (DenseLayer& layer : model.layers) {
    for (float& w : layer.weights) w = weight(rng);
    for (float& b : layer.bias) b = weight(rng);
  }
  return model;
}

// A 30 x 30 plane of unit spacing, and with `rows` dense rows (0.1 apart along x) across it,
// as a tessellation's vertices crowd along a feature curve; displaced along z by Gaussian noise
// of `sigma` spacings.
PointCloud plane_with_dense_rows(int rows, float sigma = 0.0f) {
  std::mt19937_64 rng(11);
  std::normal_distribution<float> noise(0.0f, std::max(sigma, 1e-6f));
  auto z = [&] { return sigma > 0 ? noise(rng) : 0.0f; };
  PointCloud cloud;
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 30; ++x) cloud.push_back(float(x), float(y), z());
  for (int row = 0; row < rows; ++row)
    for (int i = 0; i < 290; ++i) cloud.push_back(0.1f * float(i), 14.4f + 0.1f * float(row), z());
  return cloud;
}

// A sampling gate passes mesh-vertex clouds on to a noise-gated network: each cloud gets one of
// three networks, and the area-weighted one runs on area-weighted features.
TEST(GateChain, EachCloudGetsOneNetworkOfTheChain) {
  const Model clean_network = random_network(3, true);
  const Model mesh_vertex = constant_model(0).with_gate(GateKind::noise, clean_network, 0.1f);
  const Model chain = constant_model(1).with_gate(GateKind::sampling, mesh_vertex, 0.98f);
  ASSERT_EQ(chain.gate_chain().size(), 2u);

  const PointCloud even = plane_with_dense_rows(0), clean = plane_with_dense_rows(3);
  const PointCloud noisy = plane_with_dense_rows(3, 0.3f);
  const Classification on_even = classify(even, chain);
  EXPECT_EQ(network_name(on_even.gates), "default");  // the second gate is not asked
  EXPECT_EQ(on_even.labels, std::vector<std::uint8_t>(even.size(), 1));
  const Classification on_noisy = classify(noisy, chain);
  EXPECT_EQ(network_name(on_noisy.gates), "mesh-vertex/noisy");
  EXPECT_EQ(on_noisy.labels, std::vector<std::uint8_t>(noisy.size(), 0));

  const Classification on_clean = classify(clean, chain);
  ASSERT_EQ(network_name(on_clean.gates), "mesh-vertex/low-noise");
  EXPECT_EQ(&chain.answering_network(on_clean.gates), chain.gate_network->gate_network.get());
  const Classification alone = classify_ungated(clean, clean_network);
  EXPECT_EQ(on_clean.labels, alone.labels);
  EXPECT_EQ(on_clean.p_sharp, alone.p_sharp);
  // The same weights on counted neighbours answer otherwise: the area weights were used.
  Model counting = clean_network;
  counting.config.area_weights = false;
  EXPECT_NE(classify_ungated(clean, counting).p_sharp, alone.p_sharp);

  // Decisions that do not fit the chain are refused.
  EXPECT_THROW(chain.answering_network({{GateKind::noise, 0.1f, 1.0, true}}), Error);
}

// ln r8 spread evenly over [0, 1) in 100 points: P10 and P90 within a bin of 0.1 and 0.9.
TEST(SamplingGate, SpreadIsTheNinetiethLessTheTenthPercentileOfLnSpacing) {
  GateTally tally(GateKind::sampling, 0.5f);
  for (int i = 0; i < 100; ++i) tally.add(std::exp(2.0f * float(i) / 100.0f));  // r^2
  EXPECT_NEAR(tally.statistic(), 0.8, 2.0 / GateTally::kBinsPerUnit);
  EXPECT_TRUE(tally.gate_network_answers());
  GateTally even(GateKind::sampling, 0.5f);
  for (int i = 0; i < 100; ++i) even.add(4.0f);
  EXPECT_EQ(even.statistic(), 0.0);
  EXPECT_FALSE(even.gate_network_answers());
  even.add(0.0f);  // a duplicate point: the lowest bin, no NaN
  even.add(std::nanf(""));
  even.add(std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isfinite(even.statistic()));
  EXPECT_FALSE(GateTally(GateKind::sampling, 0.5f).gate_network_answers());  // no points
}

TEST(SamplingGate, ChoosesTheMeshVertexNetworkOnlyForUnevenSpacing) {
  const Model gated = constant_model(1).with_gate(GateKind::sampling, constant_model(0), 0.98f);
  const PointCloud even = plane_with_dense_rows(0), uneven = plane_with_dense_rows(3);

  const Classification grid = classify(even, gated);
  expect_answered_by(grid, false, even.size());
  // Inside, the 8th nearest is a diagonal neighbour (sqrt 2); along the border up to 2 apart.
  EXPECT_NEAR(grid.gates[0].statistic, std::log(2.0 / std::sqrt(2.0)),
              1.0 / GateTally::kBinsPerUnit);
  // About half the points 0.1 apart, half 1 apart: ln(P90 / P10) near ln 10.
  const Classification rows = classify(uneven, gated);
  expect_answered_by(rows, true, uneven.size());
  EXPECT_GT(rows.gates[0].statistic, 1.5);
  EXPECT_EQ(network_name(rows.gates), "mesh-vertex");
}

TEST(GateSample, ReadsEveryPointOfASmallCloudAndAboutAFixedNumberOfALargeOne) {
  for (const GateKind kind : {GateKind::noise, GateKind::sampling}) {
    const std::uint64_t size = gate_sample_size(kind);
    for (std::uint64_t i = 0; i < size; ++i) ASSERT_TRUE(gate_reads(kind, i, size));
    for (const std::uint64_t points : {size + 1, 8 * size}) {
      std::uint64_t read = 0;
      for (std::uint64_t i = 0; i < points; ++i) read += gate_reads(kind, i, points);
      // A binomial count: its standard deviation is below sqrt(size).
      EXPECT_NEAR(double(read), double(size), 5.0 * std::sqrt(double(size))) << points;
    }
  }
  EXPECT_EQ(kNoiseGatePoints, std::uint64_t(1) << 14);
  EXPECT_EQ(kSamplingGatePoints, std::uint64_t(1) << 17);
}

TEST(SamplingGate, ALargeCloudsSampleSpreadsAsTheWholeCloud) {
  // 160k grid points of unit spacing and 120k in dense rows: the sample's ln(P90 / P10) within
  // two bins of every point's, and the same choice.
  PointCloud cloud;
  for (int y = 0; y < 400; ++y)
    for (int x = 0; x < 400; ++x) cloud.push_back(float(x), float(y), 0.0f);
  for (int row = 0; row < 3; ++row)
    for (int i = 0; i < 40000; ++i)
      cloud.push_back(0.01f * float(i), 200.4f + 0.1f * float(row), 0.0f);
  ASSERT_GT(cloud.size(), kSamplingGatePoints);
  const Model gated = constant_model(1).with_gate(GateKind::sampling, constant_model(0), 0.98f);
  const std::uint8_t bit = gate_read_bit(GateKind::sampling);
  std::vector<std::uint8_t> every(cloud.size(), bit), sample(cloud.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (gate_reads(GateKind::sampling, i, cloud.size())) sample[i] = bit;
  const GateTally whole = gate_tallies(cloud, gated, every)[0];
  const GateTally sampled = gate_tallies(cloud, gated, sample)[0];
  EXPECT_EQ(whole.points(), cloud.size());
  EXPECT_LT(sampled.points(), cloud.size());
  EXPECT_NEAR(sampled.statistic(), whole.statistic(), 2.0 / GateTally::kBinsPerUnit);
  EXPECT_EQ(sampled.gate_network_answers(), whole.gate_network_answers());
  // Points read by a noise gate only are not a sampling gate's.
  const std::vector<std::uint8_t> noise_only(cloud.size(), gate_read_bit(GateKind::noise));
  EXPECT_EQ(gate_tallies(cloud, gated, noise_only)[0].points(), 0u);

  GateTally merged = gated.new_tally();
  merged.merge(sampled);
  EXPECT_EQ(merged.counts(), GateTally(sampled).counts());
  EXPECT_THROW(merged.merge(GateTally(GateKind::noise, 0.1f)), Error);
}

// The opt-in models/bounded-3c-cad-vertices.json is the shipped 3-class model with a third
// network behind a noise gate on its mesh-vertex network: the same answers wherever that gate
// does not pass a cloud on.
TEST(ShippedModels, TheCadVertexModelExtendsTheDefaultModel) {
  const std::string models = std::string(GLINT_TEST_DATA_DIR) + "/../../models/";
  const Model shipped = Model::load(models + "bounded-3c.json");
  const Model chain = Model::load(models + "bounded-3c-cad-vertices.json");
  ASSERT_EQ(shipped.gate_chain().size(), 1u);
  ASSERT_EQ(chain.gate_chain().size(), 2u);
  EXPECT_EQ(chain.gate_kind, shipped.gate_kind);
  EXPECT_EQ(chain.gate_threshold, shipped.gate_threshold);
  EXPECT_EQ(chain.layers.back().weights, shipped.layers.back().weights);
  const Model& mesh_vertex = *chain.gate_network;
  EXPECT_EQ(mesh_vertex.layers.back().weights, shipped.gate_network->layers.back().weights);
  EXPECT_EQ(mesh_vertex.input_mean, shipped.gate_network->input_mean);
  EXPECT_EQ(mesh_vertex.gate_kind, GateKind::noise);
  EXPECT_EQ(mesh_vertex.gate_threshold, 0.01f);
  EXPECT_TRUE(mesh_vertex.gate_network->config.area_weights);
  EXPECT_FALSE(mesh_vertex.config.area_weights);
}

class GateFile : public ::testing::Test {
 protected:
  GateFile()
      : folder_(std::filesystem::temp_directory_path() /
                ("glint_gate_test_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(folder_);
  }
  ~GateFile() override { std::filesystem::remove_all(folder_); }
  std::string path(const std::string& name) const { return (folder_ / name).string(); }

  std::filesystem::path folder_;
};

TEST_F(GateFile, RoundTripIsExact) {
  Model low_noise = constant_model(0);
  low_noise.layers[2].weights[5] = 0.123456789f;
  low_noise.training_info = {{"notes", "clean parts"}};
  const Model gated = constant_model(1).with_gate(GateKind::noise, low_noise, 0.0712345f);
  gated.save(path("gated.json"));
  const Model loaded = Model::load(path("gated.json"));
  ASSERT_TRUE(loaded.gated());
  EXPECT_EQ(loaded.gate_threshold, 0.0712345f);
  EXPECT_EQ(loaded.gate_kind, GateKind::noise);
  EXPECT_EQ(loaded.layers.back().bias, gated.layers.back().bias);
  EXPECT_EQ(loaded.gate_network->layers[2].weights, low_noise.layers[2].weights);
  EXPECT_EQ(loaded.gate_network->training_info, low_noise.training_info);
  EXPECT_FALSE(loaded.gate_network->gated());
  EXPECT_EQ(loaded.to_json(), gated.to_json());

  const Model by_sampling = constant_model(1).with_gate(GateKind::sampling, low_noise, 0.98125f);
  by_sampling.save(path("sampling.json"));
  const Model sampling = Model::load(path("sampling.json"));
  EXPECT_EQ(sampling.gate_kind, GateKind::sampling);
  EXPECT_EQ(sampling.gate_threshold, 0.98125f);
  EXPECT_EQ(sampling.to_json(), by_sampling.to_json());
  EXPECT_TRUE(sampling.to_json().contains("sampling_gate"));
  EXPECT_FALSE(sampling.to_json().contains("noise_gate"));

  // A chain: the sampling gate's network holds a noise gate whose network weighs by area.
  const Model chain = constant_model(1).with_gate(
      GateKind::sampling,
      constant_model(2).with_gate(GateKind::noise, random_network(5, true), 0.0125f), 0.98125f);
  chain.save(path("chain.json"));
  const Model loaded_chain = Model::load(path("chain.json"));
  ASSERT_EQ(loaded_chain.gate_chain().size(), 2u);
  const Model& last = *loaded_chain.gate_network->gate_network;
  EXPECT_TRUE(last.config.area_weights);
  EXPECT_FALSE(loaded_chain.gate_network->config.area_weights);
  EXPECT_EQ(last.layers[0].weights, random_network(5, true).layers[0].weights);
  EXPECT_EQ(loaded_chain.gate_network->gate_threshold, 0.0125f);
  EXPECT_EQ(loaded_chain.to_json(), chain.to_json());
  EXPECT_EQ(chain.to_json()["sampling_gate"]["mesh_vertices"]["noise_gate"]["low_noise"]
                           ["neighbour_weights"],
            "area");
}

}  // namespace
}  // namespace glint::edges
