// BoundED network definition, plain-C++ inference and the model file (edges/model.h).
#include "edges/model.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <tuple>

#include "core/error.h"
#include "edges/classifier.h"

namespace glint::edges {
namespace {

Model random_model(const ModelConfig& config, std::uint64_t seed) {
  Model model(config);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> weight(-0.6f, 0.6f), mean(-1.0f, 1.0f), std(0.2f, 3.0f);
  for (float& m : model.input_mean) m = mean(rng);
  for (float& s : model.input_std) s = std(rng);
  for (DenseLayer& layer : model.layers) {
    for (float& w : layer.weights) w = weight(rng);
    for (float& b : layer.bias) b = weight(rng);
  }
  return model;
}

FeatureMatrix random_features(std::size_t points, int scales, std::uint64_t seed,
                              int per_scale = kThesisFeaturesPerScale) {
  FeatureMatrix features;
  features.points = points;
  features.scales = scales;
  features.per_scale = per_scale;
  features.values.resize(points * features.row_size());
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> value(0.0f, 1.5f);
  for (float& v : features.values) v = value(rng);
  return features;
}

// One point through the network, written as plainly as possible (double accumulation).
std::vector<double> reference_forward(const Model& model, const float* row) {
  const ModelConfig& config = model.config;
  auto dense = [&](const DenseLayer& layer, const std::vector<double>& in, bool activate) {
    std::vector<double> out(layer.outputs);
    for (int o = 0; o < layer.outputs; ++o) {
      double sum = layer.bias[o];
      for (int i = 0; i < layer.inputs; ++i) sum += layer.weights[o * layer.inputs + i] * in[i];
      out[o] = activate && sum < 0 ? config.leaky_slope * sum : sum;
    }
    return out;
  };
  std::vector<std::vector<double>> vectors;
  for (std::size_t s = 0; s < config.scales.size(); ++s) {
    const int per_scale = config.features_per_scale();
    std::vector<double> v(per_scale);
    for (int f = 0; f < per_scale; ++f) {
      const std::size_t c = s * per_scale + f;
      v[f] = (double(row[c]) - model.input_mean[c]) / model.input_std[c];
    }
    vectors.push_back(v);
  }
  std::size_t layer = 0;
  while (vectors.size() > 2) {
    std::vector<std::vector<double>> fused;
    for (std::size_t j = 0; j < vectors.size() / 2; ++j) {
      std::vector<double> pair = vectors[2 * j];
      pair.insert(pair.end(), vectors[2 * j + 1].begin(), vectors[2 * j + 1].end());
      fused.push_back(dense(model.layers[layer++], pair, true));
    }
    vectors = fused;
  }
  std::vector<double> x = vectors[0];
  x.insert(x.end(), vectors[1].begin(), vectors[1].end());
  for (int h = 0; h < config.hidden_layers; ++h) x = dense(model.layers[layer++], x, true);
  x = dense(model.layers[layer], x, false);
  const double max_logit = *std::max_element(x.begin(), x.end());
  double sum = 0;
  for (double& v : x) sum += (v = std::exp(v - max_logit));
  for (double& v : x) v /= sum;
  return x;
}

class TempDir {
 public:
  TempDir()
      : path_(std::filesystem::temp_directory_path() /
              ("glint_model_test_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

TEST(ModelTest, ParameterCountMatchesTheThesis) {
  // 2 x 300 (fusion) + 400 + 272 + 272 (hidden) + 51 (output): the thesis's "1.6k".
  EXPECT_EQ(Model(ModelConfig{}).parameter_count(), 1595u);
  ModelConfig two_classes;
  two_classes.classes = 2;
  EXPECT_EQ(Model(two_classes).parameter_count(), 1595u - 17u);
  // The angular gap: 2 x 26 inputs in the first fusion level, 12 outputs each.
  ModelConfig angular_gap;
  angular_gap.angular_gap = true;
  EXPECT_EQ(Model(angular_gap).parameter_count(), 1595u + 2u * 2u * 12u);
}

TEST(ModelTest, LayersFollowTheFusionTree) {
  ModelConfig config;
  config.scales = {128, 91, 64, 45, 32, 23, 16, 11};
  const std::vector<DenseLayer> layers = make_layers(config);
  std::vector<std::string> names;
  for (const DenseLayer& layer : layers) names.push_back(layer.name);
  EXPECT_EQ(names, (std::vector<std::string>{"fusion0.0", "fusion0.1", "fusion0.2", "fusion0.3",
                                             "fusion1.0", "fusion1.1", "hidden0", "hidden1",
                                             "hidden2", "output"}));
  EXPECT_EQ(Model(config).parameter_count(), 6u * 300u + 995u);

  config.scales = {128, 32};  // no fusion node: the two vectors go straight to the head
  EXPECT_EQ(make_layers(config).front().name, "hidden0");
  EXPECT_EQ(Model(config).parameter_count(), 995u);
}

TEST(ModelTest, RejectsConfigsThatDescribeNoNetwork) {
  auto rejects = [](auto change) {
    ModelConfig config;
    change(config);
    EXPECT_THROW(check_config(config), Error);
  };
  rejects([](ModelConfig& c) { c.classes = 4; });
  rejects([](ModelConfig& c) { c.scales = {128, 64, 32}; });
  rejects([](ModelConfig& c) { c.scales = {64}; });
  rejects([](ModelConfig& c) { c.scales = {16, 32, 64, 128}; });
  rejects([](ModelConfig& c) { c.fusion_width = 0; });
  rejects([](ModelConfig& c) { c.hidden = 0; });
  rejects([](ModelConfig& c) { c.leaky_slope = std::nanf(""); });
  EXPECT_NO_THROW(check_config(ModelConfig{}));
}

TEST(ModelTest, ClassifyGivesEveryPointItsOwnFeaturesResult) {
  // classify() runs the network on blocks of features as they are computed, in the search's
  // order: each point must still get the result of its own row.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  PointCloud cloud;
  for (int i = 0; i < 3000; ++i) {
    const float a = u(rng), b = u(rng);
    cloud.push_back(a, b, std::abs(a - 0.5f));  // a crease along a = 0.5
  }
  // Also with the inputs the model's file names (area weights, angular gap).
  for (const bool area_weights : {false, true}) {
    ModelConfig config;
    config.leaky_slope = 0.1f;
    config.angular_gap = area_weights;
    config.area_weights = area_weights;
    const Model model = random_model(config, 11);
    const Classification fused = classify(cloud, model);
    const Classification apart =
        classify_features(compute_features(cloud, config.feature_params()), model);
    ASSERT_EQ(fused.labels.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      ASSERT_EQ(fused.labels[i], apart.labels[i]) << "point " << i;
      ASSERT_NEAR(fused.p_sharp[i], apart.p_sharp[i], 1e-6f) << "point " << i;
      ASSERT_NEAR(fused.p_boundary[i], apart.p_boundary[i], 1e-6f) << "point " << i;
    }
    EXPECT_GE(fused.features_s, 0.0);
    EXPECT_GE(fused.inference_s, 0.0);
  }
}

TEST(ModelTest, ZeroWeightsGiveTheSoftmaxOfTheOutputBias) {
  Model model;
  model.layers.back().bias = {0.0f, std::log(2.0f), 0.0f};
  const FeatureMatrix features = random_features(5, 4, 1);
  std::vector<float> probabilities;
  std::vector<std::uint8_t> labels;
  model.predict(features, probabilities, labels);
  ASSERT_EQ(probabilities.size(), 15u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_NEAR(probabilities[3 * i + 0], 0.25f, 1e-6f);
    EXPECT_NEAR(probabilities[3 * i + 1], 0.50f, 1e-6f);
    EXPECT_NEAR(probabilities[3 * i + 2], 0.25f, 1e-6f);
    EXPECT_EQ(labels[i], 1);
  }
}

TEST(ModelTest, PredictMatchesAPlainReferenceAcrossBatches) {
  for (const auto& scales : {std::vector<int>{128, 64, 32, 16}, std::vector<int>{128, 32},
                             std::vector<int>{128, 91, 64, 45, 32, 23, 16, 11}}) {
    for (const auto& [classes, angular_gap] :
         {std::pair{3, false}, std::pair{2, false}, std::pair{3, true}}) {
      ModelConfig config;
      config.scales = scales;
      config.classes = classes;
      config.angular_gap = angular_gap;
      config.leaky_slope = 0.1f;
      const Model model = random_model(config, 7);
      const FeatureMatrix features =  // 4 batches
          random_features(1000, int(scales.size()), 3, config.features_per_scale());
      std::vector<float> probabilities;
      std::vector<std::uint8_t> labels;
      model.predict(features, probabilities, labels);
      ASSERT_EQ(probabilities.size(), 1000u * classes);
      for (std::size_t i = 0; i < features.points; ++i) {
        const std::vector<double> expected = reference_forward(model, features.row(i));
        for (int c = 0; c < classes; ++c)
          ASSERT_NEAR(probabilities[i * classes + c], expected[c], 1e-5) << "point " << i;
        const auto best = std::max_element(expected.begin(), expected.end()) - expected.begin();
        EXPECT_EQ(labels[i], best);
      }
    }
  }
}

TEST(ModelTest, PredictHandlesNoPointsAndRejectsOtherScaleCounts) {
  const Model model = random_model(ModelConfig{}, 1);
  std::vector<float> probabilities{1.0f};
  std::vector<std::uint8_t> labels{1};
  model.predict(random_features(0, 4, 1), probabilities, labels);
  EXPECT_TRUE(probabilities.empty());
  EXPECT_TRUE(labels.empty());
  EXPECT_THROW(model.predict(random_features(3, 2, 1), probabilities, labels), Error);
  FeatureMatrix short_values = random_features(3, 4, 1);
  short_values.values.pop_back();
  EXPECT_THROW(model.predict(short_values, probabilities, labels), Error);
  // Features with the angular gap for a model of the thesis's twelve inputs.
  EXPECT_THROW(
      model.predict(random_features(3, 4, 1, kThesisFeaturesPerScale + 1), probabilities, labels),
      Error);
}

TEST(ModelTest, SaveLoadRoundTripIsExact) {
  TempDir dir;
  for (const auto& [classes, angular_gap, area_weights] :
       {std::tuple{3, false, false}, std::tuple{2, false, false}, std::tuple{3, true, false},
        std::tuple{3, true, true}}) {
    ModelConfig config;
    config.classes = classes;
    config.angular_gap = angular_gap;
    config.area_weights = area_weights;
    Model model = random_model(config, 11 + classes);
    model.input_std[5] = Model::kMinInputStd;
    model.layers[0].weights[0] = 1e-30f;           // tiny and
    model.layers[1].weights[3] = -3.40282347e38f;  // huge floats survive too
    model.training_info = {{"command", "glint edges train a.ply -o m.json"}, {"seed", 5}};
    const std::string path =
        dir.file("model" + std::to_string(classes) + (angular_gap ? "gap" : "") +
                 (area_weights ? "area" : "") + ".json");
    model.save(path);

    const Model loaded = Model::load(path);
    EXPECT_EQ(loaded.config.classes, classes);
    EXPECT_EQ(loaded.config.angular_gap, angular_gap);
    EXPECT_EQ(loaded.config.area_weights, area_weights);
    EXPECT_EQ(loaded.config.scales, config.scales);
    EXPECT_EQ(loaded.config.fusion_width, config.fusion_width);
    EXPECT_EQ(loaded.config.hidden, config.hidden);
    EXPECT_EQ(loaded.config.hidden_layers, config.hidden_layers);
    EXPECT_EQ(loaded.config.leaky_slope, config.leaky_slope);
    EXPECT_EQ(loaded.input_mean, model.input_mean);
    EXPECT_EQ(loaded.input_std, model.input_std);
    ASSERT_EQ(loaded.layers.size(), model.layers.size());
    for (std::size_t l = 0; l < model.layers.size(); ++l) {
      EXPECT_EQ(loaded.layers[l].name, model.layers[l].name);
      EXPECT_EQ(loaded.layers[l].weights, model.layers[l].weights);
      EXPECT_EQ(loaded.layers[l].bias, model.layers[l].bias);
    }
    EXPECT_EQ(loaded.training_info, model.training_info);
    EXPECT_EQ(loaded.parameter_count(), model.parameter_count());
  }
}

// Model files written before area weights existed have no "neighbour_weights": they load as
// counts, the neighbours weighing 1.
TEST(ModelTest, FilesWithoutNeighbourWeightsCountNeighbours) {
  TempDir dir;
  ModelConfig config;
  config.area_weights = true;
  nlohmann::json json = random_model(config, 5).to_json();
  EXPECT_EQ(json["neighbour_weights"], "area");
  json.erase("neighbour_weights");
  const std::string path = dir.file("older.json");
  std::ofstream(path) << json.dump();
  EXPECT_FALSE(Model::load(path).config.area_weights);
}

// Writes `json` to a file, lets `damage` change it first, and expects load() to name the key.
class MalformedModelTest : public ::testing::Test {
 protected:
  void expect_rejected(const std::function<void(nlohmann::json&)>& damage,
                       const std::string& element,
                       nlohmann::json json = random_model(ModelConfig{}, 3).to_json()) {
    damage(json);
    const std::string path = dir_.file("broken.json");
    std::ofstream(path) << json.dump();
    try {
      Model::load(path);
      FAIL() << "accepted a model with a broken " << element;
    } catch (const Error& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_NE(e.element().find(element), std::string::npos) << e.what();
    }
  }
  TempDir dir_;
};

TEST_F(MalformedModelTest, MissingKeys) {
  for (const char* key :
       {"format", "version", "classes", "scales", "features_per_scale", "fusion_width", "hidden",
        "hidden_layers", "leaky_slope", "input_mean", "input_std", "layers", "parameter_count"})
    expect_rejected([key](nlohmann::json& j) { j.erase(key); }, key);
  expect_rejected([](nlohmann::json& j) { j["layers"][2].erase("bias"); }, "layers[2].bias");
}

TEST_F(MalformedModelTest, WrongSizesAndShapes) {
  expect_rejected([](nlohmann::json& j) { j["input_mean"].erase(0); }, "input_mean");
  expect_rejected([](nlohmann::json& j) { j["layers"][1]["weights"].push_back(0.5); },
                  "layers[1].weights");
  expect_rejected([](nlohmann::json& j) { j["layers"].erase(4); }, "layers");
  expect_rejected([](nlohmann::json& j) { j["layers"][0]["inputs"] = 12; }, "layers[0]");
  expect_rejected([](nlohmann::json& j) { j["scales"] = {128, 64, 32}; }, "scales");
  expect_rejected([](nlohmann::json& j) { j["features_per_scale"] = 14; }, "features_per_scale");
  // 13 inputs per scale, but input arrays and layers sized for 12.
  expect_rejected([](nlohmann::json& j) { j["features_per_scale"] = 13; }, "input_mean");
  expect_rejected([](nlohmann::json& j) { j["parameter_count"] = 1600; }, "parameter_count");
}

TEST_F(MalformedModelTest, WrongValues) {
  // JSON has no NaN: nlohmann writes it as null; an overflowing number is not a finite float.
  expect_rejected([](nlohmann::json& j) { j["layers"][3]["weights"][7] = std::nan(""); },
                  "layers[3].weights[7]");
  expect_rejected([](nlohmann::json& j) { j["layers"][3]["bias"][0] = 1e300; },
                  "layers[3].bias[0]");
  expect_rejected([](nlohmann::json& j) { j["input_std"][2] = 0.0; }, "input_std[2]");
  expect_rejected([](nlohmann::json& j) { j["input_mean"][2] = "0.5"; }, "input_mean[2]");
  expect_rejected([](nlohmann::json& j) { j["format"] = "pcednet"; }, "format");
  expect_rejected([](nlohmann::json& j) { j["version"] = 2; }, "version");
  expect_rejected([](nlohmann::json& j) { j["classes"] = {"a", "b", "c"}; }, "classes");
  expect_rejected([](nlohmann::json& j) { j["training"] = 3; }, "training");
  expect_rejected([](nlohmann::json& j) { j["neighbour_weights"] = "density"; },
                  "neighbour_weights");
  expect_rejected([](nlohmann::json& j) { j["neighbour_weights"] = 1; }, "neighbour_weights");
}

TEST_F(MalformedModelTest, BrokenGates) {
  const nlohmann::json gated = random_model(ModelConfig{}, 3)
                                   .with_gate(GateKind::noise, random_model(ModelConfig{}, 4), 0.1f)
                                   .to_json();
  auto rejects = [&](auto damage, const std::string& element) {
    expect_rejected(damage, element, gated);
  };
  rejects([](nlohmann::json& j) { j["noise_gate"] = 3; }, "noise_gate");
  rejects([](nlohmann::json& j) { j["noise_gate"].erase("threshold"); }, "noise_gate.threshold");
  rejects([](nlohmann::json& j) { j["noise_gate"]["threshold"] = -0.5; }, "noise_gate.threshold");
  rejects([](nlohmann::json& j) { j["noise_gate"].erase("low_noise"); }, "noise_gate.low_noise");
  rejects([](nlohmann::json& j) { j["noise_gate"]["low_noise"]["layers"][4].erase("bias"); },
          "noise_gate.low_noise.layers[4].bias");
  rejects([](nlohmann::json& j) { j["noise_gate"]["low_noise"]["input_std"][0] = 0.0; },
          "noise_gate.low_noise.input_std[0]");
  rejects([](nlohmann::json& j) { j["noise_gate"]["low_noise"]["parameter_count"] = 7; },
          "noise_gate.low_noise.parameter_count");
  // A sampling gate names its network mesh_vertices; a file holds one gate.
  const nlohmann::json by_sampling =
      random_model(ModelConfig{}, 3)
          .with_gate(GateKind::sampling, random_model(ModelConfig{}, 4), 0.98f)
          .to_json();
  expect_rejected([](nlohmann::json& j) { j["sampling_gate"].erase("mesh_vertices"); },
                  "sampling_gate.mesh_vertices", by_sampling);
  expect_rejected([](nlohmann::json& j) { j["sampling_gate"]["threshold"] = 0; },
                  "sampling_gate.threshold", by_sampling);
  expect_rejected([&](nlohmann::json& j) { j["noise_gate"] = gated["noise_gate"]; },
                  "sampling_gate", by_sampling);
  // A chain: the errors of the inner gate name its whole key path.
  ModelConfig area;
  area.area_weights = true;
  const nlohmann::json chain =
      random_model(ModelConfig{}, 3)
          .with_gate(GateKind::sampling,
                     random_model(ModelConfig{}, 4)
                         .with_gate(GateKind::noise, random_model(area, 5), 0.01f),
                     0.98f)
          .to_json();
  const std::string inner = "sampling_gate.mesh_vertices.noise_gate";
  expect_rejected(
      [](nlohmann::json& j) {
        j["sampling_gate"]["mesh_vertices"]["noise_gate"]["low_noise"]["neighbour_weights"] =
            "volume";
      },
      inner + ".low_noise.neighbour_weights", chain);
  expect_rejected(
      [](nlohmann::json& j) {
        j["sampling_gate"]["mesh_vertices"]["noise_gate"]["low_noise"]["layers"][0].erase("bias");
      },
      inner + ".low_noise.layers[0].bias", chain);
  expect_rejected(
      [](nlohmann::json& j) { j["sampling_gate"]["mesh_vertices"]["noise_gate"]["threshold"] = 0; },
      inner + ".threshold", chain);
}

TEST_F(MalformedModelTest, NotJsonOrNoFile) {
  const std::string path = dir_.file("garbage.json");
  std::ofstream(path) << "{\"format\": \"glint-bounded-model\", \"weights\": [NaN]}";
  EXPECT_THROW(Model::load(path), Error);
  EXPECT_THROW(Model::load(dir_.file("does-not-exist.json")), Error);
  std::ofstream(dir_.file("array.json")) << "[1, 2, 3]";
  EXPECT_THROW(Model::load(dir_.file("array.json")), Error);
}

}  // namespace
}  // namespace glint::edges
