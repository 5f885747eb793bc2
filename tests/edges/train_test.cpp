// Training the BoundED network with libtorch (edges/train.h) and its agreement with the
// plain-C++ inference of edges/model.h.
#include "edges/train.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.h"
#include "core/parallel.h"

namespace glint::edges {
namespace {

FeatureMatrix random_features(std::size_t points, int scales, std::uint64_t seed) {
  FeatureMatrix features;
  features.points = points;
  features.scales = scales;
  features.values.resize(points * features.row_size());
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> value(0.0f, 1.0f);
  for (float& v : features.values) v = value(rng);
  return features;
}

// Three classes told apart by two features of different scales, with a margin, and an offset
// and scale per column so that the standardisation matters:
// sharp where x > 0.3, else boundary where y > 0.3, else non-edge (|x|, |y| >= 0.3 everywhere).
TrainingSet separable_problem(std::size_t points, std::uint64_t seed) {
  TrainingSet set{random_features(points, 4, seed), std::vector<std::uint8_t>(points)};
  const int x_column = 0 * kThesisFeaturesPerScale + 6, y_column = 3 * kThesisFeaturesPerScale + 9;
  for (std::size_t i = 0; i < points; ++i) {
    float* row = set.features.row(i);
    for (int column : {x_column, y_column}) row[column] += row[column] >= 0 ? 0.3f : -0.3f;
    set.labels[i] = row[x_column] > 0 ? 1 : row[y_column] > 0 ? 2 : 0;
    for (std::size_t c = 0; c < set.features.row_size(); ++c) row[c] = 5.0f + 40.0f * c * row[c];
  }
  return set;
}

TrainParams short_training(int iterations) {
  TrainParams params;
  params.iterations = iterations;
  params.batch_size = 128;
  params.log_every = 10;
  params.validation_fraction = 0.1;
  return params;
}

void expect_torch_agrees(const Model& model, const FeatureMatrix& features) {
  std::vector<float> probabilities;
  std::vector<std::uint8_t> labels;
  model.predict(features, probabilities, labels);
  const std::vector<float> expected = torch_predict(model, features);
  ASSERT_EQ(probabilities.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    ASSERT_NEAR(probabilities[i], expected[i], 1e-5) << "value " << i;
}

std::vector<float> all_weights(const Model& model) {
  std::vector<float> weights = model.input_mean;
  weights.insert(weights.end(), model.input_std.begin(), model.input_std.end());
  for (const DenseLayer& layer : model.layers) {
    weights.insert(weights.end(), layer.weights.begin(), layer.weights.end());
    weights.insert(weights.end(), layer.bias.begin(), layer.bias.end());
  }
  return weights;
}

TEST(TrainTest, PlainInferenceEqualsTorchForRandomWeights) {
  for (int classes : {3, 2}) {
    for (const auto& scales : {std::vector<int>{128, 64, 32, 16}, std::vector<int>{128, 32},
                               std::vector<int>{128, 91, 64, 45, 32, 23, 16, 11}}) {
      ModelConfig config;
      config.classes = classes;
      config.scales = scales;
      Model model(config);
      std::mt19937_64 rng(classes);
      std::uniform_real_distribution<float> weight(-0.7f, 0.7f), std(0.3f, 2.0f);
      for (float& m : model.input_mean) m = weight(rng);
      for (float& s : model.input_std) s = std(rng);
      for (DenseLayer& layer : model.layers) {
        for (float& w : layer.weights) w = weight(rng);
        for (float& b : layer.bias) b = weight(rng);
      }
      expect_torch_agrees(model, random_features(700, int(scales.size()), 5));
    }
  }
}

TEST(TrainTest, PlainInferenceEqualsTorchAfterTraining) {
  const TrainingSet data = separable_problem(2000, 3);
  const Model model = train_model(data, ModelConfig{}, short_training(30));
  expect_torch_agrees(model, data.features);
}

TEST(TrainTest, SameSeedGivesBitIdenticalWeights) {
  const auto one_thread = limit_threads(1);
  const TrainingSet data = separable_problem(1000, 4);
  TrainParams params = short_training(20);
  const std::vector<float> first = all_weights(train_model(data, ModelConfig{}, params));
  const std::vector<float> second = all_weights(train_model(data, ModelConfig{}, params));
  EXPECT_EQ(first, second);
  params.seed = 2;
  EXPECT_NE(first, all_weights(train_model(data, ModelConfig{}, params)));
  params.seed = 1;
  params.balance_classes = true;
  EXPECT_NE(first, all_weights(train_model(data, ModelConfig{}, params)));
}

TEST(TrainTest, LearnsASeparableProblem) {
  const TrainingSet data = separable_problem(4000, 5);
  TrainParams params = short_training(400);
  params.batch_size = 512;
  params.learning_rate = 1e-2;
  const Model model = train_model(data, ModelConfig{}, params);

  const TrainingSet unseen = separable_problem(2000, 6);
  std::vector<float> probabilities;
  std::vector<std::uint8_t> labels;
  model.predict(unseen.features, probabilities, labels);
  std::size_t correct = 0;
  for (std::size_t i = 0; i < labels.size(); ++i) correct += labels[i] == unseen.labels[i];
  EXPECT_GT(double(correct) / double(labels.size()), 0.95);
}

TEST(TrainTest, StandardisesWithTheTrainingPointsAndRecordsTheRun) {
  const TrainingSet data = separable_problem(1000, 7);
  const TrainParams params = short_training(30);
  const Model model = train_model(data, ModelConfig{}, params);

  // Column c was 5 + 40 c N(0, ~1.3): the standardisation tracks that offset and spread.
  EXPECT_NEAR(model.input_mean[0], 5.0f, 0.2f);
  EXPECT_EQ(model.input_std[0], Model::kMinInputStd);  // column 0 is constant
  EXPECT_NEAR(model.input_std[20] / (40.0f * 20.0f), 1.0f, 0.15f);

  const nlohmann::json& info = model.training_info;
  std::size_t counts[3] = {0, 0, 0};
  for (std::uint8_t label : data.labels) ++counts[label];
  for (int c = 0; c < 3; ++c) {
    const std::size_t held_out = std::llround(0.1 * counts[c]);
    EXPECT_EQ(info["validation_points_per_class"][c], held_out);
    EXPECT_EQ(info["training_points_per_class"][c], counts[c] - held_out);
  }
  // The kept weights are those of the lowest validation loss in the history.
  double lowest = INFINITY;
  int lowest_at = 0;
  for (const auto& entry : info["history"])
    if (entry["validation_loss"].get<double>() < lowest) {
      lowest = entry["validation_loss"];
      lowest_at = entry["iteration"];
    }
  EXPECT_EQ(info["history"].size(), 3u);
  EXPECT_EQ(info["final"]["best_iteration"], lowest_at);
  EXPECT_EQ(info["final"]["validation_loss"], lowest);
  EXPECT_EQ(info["seed"], params.seed);
}

TEST(TrainTest, ClassWeightsAndNoValidationAreAccepted) {
  const TrainingSet data = separable_problem(500, 8);
  TrainParams params = short_training(5);
  params.class_weights = {0.25, 1.0, 1.0};
  params.validation_fraction = 0.0;
  params.focal_gamma = 0.0;  // plain weighted cross-entropy
  const Model model = train_model(data, ModelConfig{}, params);
  EXPECT_FALSE(model.training_info["final"].contains("validation_loss"));
  EXPECT_EQ(model.training_info["validation_points_per_class"], nlohmann::json({0, 0, 0}));
}

TEST(TrainTest, RejectsInconsistentDataAndParameters) {
  const TrainingSet data = separable_problem(100, 9);
  const TrainParams params = short_training(2);
  ModelConfig two_classes;
  two_classes.classes = 2;
  EXPECT_THROW(train_model(data, two_classes, params), Error);  // label 2 in a 2-class model

  TrainingSet short_labels = data;
  short_labels.labels.pop_back();
  EXPECT_THROW(train_model(short_labels, ModelConfig{}, params), Error);

  ModelConfig eight_scales;
  eight_scales.scales = {128, 91, 64, 45, 32, 23, 16, 11};
  EXPECT_THROW(train_model(data, eight_scales, params), Error);

  TrainingSet empty;
  empty.features.scales = 4;
  EXPECT_THROW(train_model(empty, ModelConfig{}, params), Error);

  auto rejects = [&](auto change) {
    TrainParams bad = params;
    change(bad);
    EXPECT_THROW(train_model(data, ModelConfig{}, bad), Error);
  };
  rejects([](TrainParams& p) { p.batch_size = 0; });
  rejects([](TrainParams& p) { p.learning_rate = 0; });
  rejects([](TrainParams& p) { p.dropout = 1.0; });
  rejects([](TrainParams& p) { p.validation_fraction = 1.0; });
  rejects([](TrainParams& p) { p.class_weights = {1.0, 2.0}; });
  rejects([](TrainParams& p) { p.class_weights = {1.0, -2.0, 1.0}; });
}

}  // namespace
}  // namespace glint::edges
