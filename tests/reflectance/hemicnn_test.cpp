// The HemiCNN (reflectance/hemicnn.h): plain-C++ inference against libtorch, order invariance,
// the model file, eq. (5), the dataset format (reflectance/hemi_dataset.h) and training
// (reflectance/hemicnn_train.h).
#include "reflectance/hemicnn.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>

#include "core/error.h"
#include "io/json_report.h"
#include "io/npy.h"
#include "reflectance/hemi_dataset.h"
#include "reflectance/hemicnn_train.h"
#include "support/error_of.h"

namespace glint::reflectance {
namespace {

using test::error_of;

class TempDir {
 public:
  TempDir()
      : path_(std::filesystem::temp_directory_path() /
              ("glint_hemicnn_test_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

HemiCnn random_model(const HemiCnnConfig& config, std::uint64_t seed) {
  HemiCnn model(config);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> weight(-0.3f, 0.3f), std(0.5f, 2.0f);
  for (int c = 0; c < 3; ++c) {
    model.input_mean[c] = weight(rng);
    model.input_std[c] = std(rng);
  }
  for (int t = 0; t < HemiCnn::kTargets; ++t) {
    model.target_mean[t] = 10 * weight(rng);
    model.target_std[t] = std(rng);
  }
  for (HemiCnnLayer& layer : model.layers) {
    for (float& w : layer.weights) w = weight(rng);
    for (float& b : layer.bias) b = weight(rng);
  }
  return model;
}

// Radiances as the pipeline sees them: mostly [0, 3], a few highlights up to 40, a few
// slightly negative (noise).
std::vector<float> random_images(std::size_t count, int size, std::uint64_t seed) {
  std::vector<float> images(count * 3 * size * size);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 3.0f), kind(0.0f, 1.0f), highlight(3.0f, 40.0f);
  for (float& v : images) {
    const float k = kind(rng);
    v = k < 0.03f ? highlight(rng) : k < 0.05f ? -0.05f : value(rng);
  }
  return images;
}

std::vector<float> raw_outputs(const HemiCnn& model, const float* images, int count) {
  HemiCnnScratch scratch;
  std::vector<float> outputs(HemiCnn::kTargets);
  model.predict_raw(images, count, scratch, outputs.data());
  return outputs;
}

TEST(HemiCnn, DefaultArchitecture) {
  const HemiCnn model;
  // conv 3->16 (448), 16->32 (4,640), 32->32 (9,248); branch 2*2*32 -> 128 (16,512);
  // head 128 -> 64 (8,256); output 64 -> 7 (455).
  EXPECT_EQ(model.parameter_count(), 39559u);
  std::vector<int> sizes;
  for (const HemiCnnLayer& layer : model.layers) sizes.push_back(layer.output_size);
  EXPECT_EQ(sizes, (std::vector<int>{8, 4, 2, 1, 1, 1}));
  EXPECT_EQ(model.layers[3].inputs, 2 * 2 * 32);
  EXPECT_EQ(model.image_floats(), 675u);
  EXPECT_EQ(model.projection(), HemiProjection::parabolic);
}

TEST(HemiCnn, RejectsConfigsThatDescribeNoNetwork) {
  auto rejects = [](auto change) {
    HemiCnnConfig config;
    change(config);
    EXPECT_THROW(check_config(config), Error);
  };
  rejects([](HemiCnnConfig& c) { c.image_size = 2; });
  rejects([](HemiCnnConfig& c) { c.conv_channels.clear(); });
  rejects([](HemiCnnConfig& c) { c.conv_channels = {16, 0}; });
  rejects([](HemiCnnConfig& c) { c.branch_features = 0; });
  rejects([](HemiCnnConfig& c) { c.head_hidden = 0; });
  rejects([](HemiCnnConfig& c) { c.leaky_slope = 1.0f; });
  EXPECT_NO_THROW(check_config(HemiCnnConfig{}));
}

TEST(HemiCnn, PlainInferenceEqualsTorch) {
  HemiCnnConfig small;
  small.image_size = 9;
  small.conv_channels = {5, 7};
  small.branch_features = 11;
  small.head_hidden = 6;
  for (const HemiCnnConfig& config : {HemiCnnConfig{}, small}) {
    const HemiCnn model = random_model(config, 3);
    for (int count : {25, 1, 7}) {
      const int sets = 3;
      const std::vector<float> images =
          random_images(std::size_t(sets) * count, config.image_size, count);
      const std::vector<float> expected = torch_predict(model, images.data(), sets, count);
      ASSERT_EQ(expected.size(), std::size_t(sets) * HemiCnn::kTargets);
      for (int s = 0; s < sets; ++s) {
        const std::vector<float> outputs = raw_outputs(
            model, images.data() + std::size_t(s) * count * model.image_floats(), count);
        for (int t = 0; t < HemiCnn::kTargets; ++t) {
          const float reference = expected[s * HemiCnn::kTargets + t];
          EXPECT_NEAR(outputs[t], reference, 1e-4f * std::max(1.0f, std::fabs(reference)))
              << "set " << s << " of " << count << ", output " << t;
        }
      }
    }
  }
}

TEST(HemiCnn, OutputDoesNotDependOnTheOrderOfTheImages) {
  const HemiCnn model = random_model(HemiCnnConfig{}, 4);
  const std::size_t floats = model.image_floats();
  const std::vector<float> images = random_images(25, 15, 5);
  std::vector<int> order(25);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(6));
  std::vector<float> permuted(images.size());
  for (int k = 0; k < 25; ++k)
    std::copy_n(images.data() + order[k] * floats, floats, permuted.data() + k * floats);
  const std::vector<float> a = raw_outputs(model, images.data(), 25);
  const std::vector<float> b = raw_outputs(model, permuted.data(), 25);
  for (int t = 0; t < HemiCnn::kTargets; ++t)
    EXPECT_NEAR(a[t], b[t], 1e-5f * std::max(1.0f, std::fabs(a[t])));
  // The thread_local overload gives the clamped form of the same outputs.
  const render::PerceptualWard ward = model.predict(images.data(), 25);
  const render::PerceptualWard expected = perceptual_from_outputs(a.data());
  EXPECT_EQ(ward.lab, expected.lab);
  EXPECT_EQ(ward.c, expected.c);
  EXPECT_EQ(ward.d, expected.d);
}

TEST(HemiCnn, ZeroWeightsGiveTheClampedTargetMean) {
  HemiCnn model;
  const float mean[HemiCnn::kTargets] = {120.0f, -5.0f, 7.0f, -0.1f, 0.05f, 0.1f, 2.0f};
  std::copy_n(mean, HemiCnn::kTargets, model.target_mean);
  const std::vector<float> images = random_images(25, 15, 1);
  const render::PerceptualWard ward = model.predict(images.data(), 25);
  EXPECT_EQ(ward.lab, Eigen::Vector3f(100.0f, -5.0f, 7.0f));
  EXPECT_EQ(ward.c, Eigen::Vector3f(0.0f, 0.05f, 0.1f));
  EXPECT_EQ(ward.d, HemiCnn::kMaxD);
  model.target_mean[6] = 0.1f;
  EXPECT_EQ(model.predict(images.data(), 3).d, HemiCnn::kMinD);
  EXPECT_EQ(error_of([&] { model.predict(images.data(), 0); }).element(), "count");
}

TEST(HemiCnn, ModelFileRoundTrip) {
  const TempDir dir;
  HemiCnnConfig config;
  config.projection = HemiProjection::orthographic;
  config.input = HemiInput::reflectance;
  HemiCnn model = random_model(config, 7);
  model.training_info = {{"note", "test"}};
  model.save(dir.file("model.json"));
  EXPECT_LT(std::filesystem::file_size(dir.file("model.json")), 1000000u);
  const HemiCnn loaded = HemiCnn::load(dir.file("model.json"));
  EXPECT_EQ(loaded.projection(), HemiProjection::orthographic);
  EXPECT_EQ(loaded.input(), HemiInput::reflectance);
  EXPECT_EQ(loaded.config.conv_channels, config.conv_channels);
  ASSERT_EQ(loaded.layers.size(), model.layers.size());
  for (std::size_t l = 0; l < model.layers.size(); ++l) {
    EXPECT_EQ(loaded.layers[l].weights, model.layers[l].weights);
    EXPECT_EQ(loaded.layers[l].bias, model.layers[l].bias);
  }
  EXPECT_TRUE(std::equal(model.target_std, model.target_std + 7, loaded.target_std));
  EXPECT_TRUE(std::equal(model.input_mean, model.input_mean + 3, loaded.input_mean));
  EXPECT_EQ(loaded.training_info["note"], "test");
  const std::vector<float> images = random_images(25, 15, 8);
  EXPECT_EQ(raw_outputs(loaded, images.data(), 25), raw_outputs(model, images.data(), 25));
}

TEST(HemiCnn, AModelFileWithoutAnInputHoldsARadianceModel) {
  // Model files written before HemiInput existed have no "input".
  const TempDir dir;
  HemiCnnConfig config;
  config.input = HemiInput::reflectance;
  nlohmann::json old_file = random_model(config, 3).to_json();
  old_file.erase("input");
  io::write_json(dir.file("old.json"), old_file);
  EXPECT_EQ(HemiCnn::load(dir.file("old.json")).input(), HemiInput::radiance);
}

TEST(HemiCnn, LoadNamesTheBadKey) {
  const TempDir dir;
  const nlohmann::json good = random_model(HemiCnnConfig{}, 9).to_json();
  auto element_of_error = [&](auto change) {
    nlohmann::json broken = good;
    change(broken);
    io::write_json(dir.file("bad.json"), broken);
    const Error e = error_of([&] { HemiCnn::load(dir.file("bad.json")); });
    EXPECT_EQ(e.file(), dir.file("bad.json"));
    return e.element();
  };
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["format"] = "glint-bounded-model"; }),
            "format");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["version"] = 2; }), "version");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j.erase("target_std"); }), "target_std");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["input_std"][1] = 0.0; }), "input_std[1]");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["projection"] = "fisheye"; }), "projection");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["input"] = "irradiance"; }), "input");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["conv_channels"] = {16, 32}; }), "layers");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["layers"][2]["weights"].erase(0); }),
            "layers[2].weights");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["layers"][0]["bias"][3] = "x"; }),
            "layers[0].bias[3]");
  EXPECT_EQ(element_of_error([](nlohmann::json& j) { j["parameter_count"] = 5; }),
            "parameter_count");
  EXPECT_THROW(HemiCnn::load(dir.file("missing.json")), Error);
}

TEST(HemiCnnLoss, IsEquationFiveInUnitsOfOneHundredLab) {
  render::PerceptualWard truth, estimate;
  estimate.lab.x() += 10.0f;  // dL = 10 -> 0.1 in loss units
  EXPECT_NEAR(hemicnn_loss(estimate, truth), 0.1 * 0.3 * 0.3 * 0.01, 1e-9);
  EXPECT_NEAR(hemicnn_loss(estimate, truth, {1.0, 1.0}), 0.01, 1e-9);
  estimate = truth;
  estimate.lab.y() -= 20.0f;
  estimate.c.z() += 0.05f;
  estimate.d -= 0.1f;
  EXPECT_NEAR(hemicnn_loss(estimate, truth), 0.1 * 0.04 + 0.0025 + 0.01, 1e-7);
}

// ---- the dataset format

render::WardMaterial material_of(std::mt19937_64& rng) {
  std::uniform_real_distribution<float> kd(0.05f, 0.9f), ks(0.0f, 0.1f), alpha(0.02f, 0.35f);
  render::WardMaterial m;
  m.kd = {kd(rng), kd(rng), kd(rng)};
  m.ks = Eigen::Vector3f::Constant(ks(rng));
  m.alpha = alpha(rng);
  return m;
}

// Hemi-images whose brightness encodes kd: each pixel is kd * irradiance / pi with an
// irradiance of 1.5-2.5 per image, plus noise.
std::vector<float> diffuse_images(const render::WardMaterial& m, int count, std::mt19937_64& rng) {
  std::vector<float> images(std::size_t(count) * 675);
  std::uniform_real_distribution<float> irradiance(1.5f, 2.5f), noise(-0.02f, 0.02f);
  for (int k = 0; k < count; ++k) {
    const float e = irradiance(rng);
    for (int c = 0; c < 3; ++c)
      for (int p = 0; p < 225; ++p) images[k * 675 + c * 225 + p] = m.kd[c] * e / M_PI + noise(rng);
  }
  return images;
}

void write_dataset(const std::string& folder, int sequences, int images_per_sequence,
                   std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  HemiDatasetWriter writer(folder, 15, HemiProjection::orthographic);
  for (int s = 0; s < sequences; ++s) {
    const render::WardMaterial m = material_of(rng);
    writer.add_sequence(diffuse_images(m, images_per_sequence, rng).data(), images_per_sequence, m,
                        "synthetic " + std::to_string(s));
  }
  writer.finish();
}

TEST(HemiDataset, RoundTrip) {
  const TempDir dir;
  std::mt19937_64 rng(1);
  HemiDatasetWriter writer(dir.file("set"), 15, HemiProjection::orthographic,
                           HemiInput::reflectance);
  const render::WardMaterial m0 = material_of(rng), m1 = material_of(rng);
  const std::vector<float> images0 = diffuse_images(m0, 25, rng),
                           images1 = diffuse_images(m1, 40, rng);
  EXPECT_EQ(writer.add_sequence(images0.data(), 25, m0, "first"), 0);
  EXPECT_EQ(writer.add_sequence(images1.data(), 40, m1, "second"), 1);
  writer.finish();

  const HemiDataset data = read_hemi_dataset(dir.file("set"));
  EXPECT_EQ(data.size, 15);
  EXPECT_EQ(data.projection, HemiProjection::orthographic);
  EXPECT_EQ(data.input, HemiInput::reflectance);
  ASSERT_EQ(data.sequences.size(), 2u);
  EXPECT_EQ(data.sequences[0].file, "seq_00000.npy");
  EXPECT_EQ(data.sequences[1].source, "second");
  EXPECT_EQ(data.sequences[1].images, 40);
  EXPECT_EQ(data.sequences[0].values, images0);
  EXPECT_EQ(data.sequences[1].values, images1);
  EXPECT_TRUE(data.sequences[1].material.kd.isApprox(m1.kd));
  EXPECT_FLOAT_EQ(data.sequences[1].material.alpha, m1.alpha);
  const render::PerceptualWard target = render::to_perceptual(m1);
  EXPECT_TRUE(data.sequences[1].target.lab.isApprox(target.lab, 1e-6f));
  EXPECT_FLOAT_EQ(data.sequences[1].target.d, target.d);
  EXPECT_EQ(data.sequences[1].image(1, 15), data.sequences[1].values.data() + 675);
}

TEST(HemiDataset, RejectsBadInputsNamingTheFile) {
  const TempDir dir;
  const std::string folder = dir.file("set");
  EXPECT_EQ(error_of([&] { read_hemi_dataset(folder); }).file(), folder + "/index.json");

  write_dataset(folder, 2, 25, 2);
  const std::string index = folder + "/index.json", npy = folder + "/seq_00001.npy";
  const nlohmann::json good_index = io::read_json(index);
  auto fails_on = [&](const std::string& expected_file) {
    const Error e = error_of([&] { read_hemi_dataset(folder); });
    EXPECT_EQ(e.file(), expected_file) << e.what();
    return e;
  };

  {  // malformed index
    std::ofstream(index) << "{\"format\": ";
    fails_on(index);
    nlohmann::json changed = good_index;
    changed["format"] = "something else";
    io::write_json(index, changed);
    EXPECT_EQ(fails_on(index).element(), "format");
    changed = good_index;
    changed["size"] = 2;
    io::write_json(index, changed);
    EXPECT_EQ(fails_on(index).element(), "size");
    changed = good_index;
    changed["input"] = "irradiance";
    io::write_json(index, changed);
    EXPECT_EQ(fails_on(index).element(), "input");
    changed.erase("input");  // datasets written before HemiInput hold radiance
    io::write_json(index, changed);
    EXPECT_EQ(read_hemi_dataset(folder).input, HemiInput::radiance);
    changed = good_index;
    changed["sequences"][1]["target"][6] = 0.5;
    io::write_json(index, changed);
    EXPECT_EQ(fails_on(index).element(), "sequences[1].target");
    changed = good_index;
    changed["sequences"][0].erase("kd");
    io::write_json(index, changed);
    EXPECT_EQ(fails_on(index).element(), "sequences[0].kd");
    changed = good_index;
    changed["size"] = 14;  // the npy files hold 15 x 15 images
    io::write_json(index, changed);
    EXPECT_EQ(fails_on(folder + "/seq_00000.npy").element(), "shape");
    io::write_json(index, good_index);
  }
  const io::NpyArray good_npy = io::read_npy(npy);
  {  // truncated npy
    const std::string bytes = [&] {
      std::ifstream in(npy, std::ios::binary);
      return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    std::ofstream(npy, std::ios::binary) << bytes.substr(0, bytes.size() - 100);
    fails_on(npy);
  }
  {  // wrong shapes, too few images, NaN
    io::write_npy(npy, {25, 3, 15, 14}, good_npy.values.data());
    EXPECT_EQ(fails_on(npy).element(), "shape");
    io::write_npy(npy, {24, 3, 15, 15}, good_npy.values.data());
    EXPECT_EQ(fails_on(npy).element(), "shape");
    std::vector<float> with_nan = good_npy.values;
    with_nan[3 * 675 + 17] = std::nanf("");
    io::write_npy(npy, {25, 3, 15, 15}, with_nan.data());
    EXPECT_EQ(fails_on(npy).element(), "hemi-image 3");
  }
  std::filesystem::remove(npy);
  fails_on(npy);
}

TEST(HemiDataset, WriterRejectsBadSequences) {
  const TempDir dir;
  HemiDatasetWriter writer(dir.file("set"));
  std::mt19937_64 rng(3);
  const render::WardMaterial m = material_of(rng);
  std::vector<float> images = diffuse_images(m, 25, rng);
  EXPECT_THROW(writer.add_sequence(images.data(), 24, m, ""), Error);
  render::WardMaterial bad = m;
  bad.alpha = 0.0f;
  EXPECT_THROW(writer.add_sequence(images.data(), 25, bad, ""), Error);
  images[100] = INFINITY;
  EXPECT_THROW(writer.add_sequence(images.data(), 25, m, ""), Error);
  EXPECT_EQ(writer.sequence_count(), 0);
  EXPECT_THROW(HemiDatasetWriter(dir.file("other"), 2), Error);
}

// ---- training

HemiCnnTrainParams short_training(int batches) {
  HemiCnnTrainParams params;
  params.batches = batches;
  params.batch_size = 8;
  params.learning_rate = 3e-3;
  params.log_every = 10;
  params.validation_fraction = 0.2;
  params.loss = {1.0, 1.0};  // the test materials differ only in kd: let the Lab term count
  return params;
}

HemiCnnConfig small_config() {
  HemiCnnConfig config;
  config.conv_channels = {8, 16, 16};
  config.branch_features = 32;
  config.head_hidden = 32;
  return config;
}

TEST(HemiCnnTrain, LowersTheValidationLossAndAgreesWithPlainInference) {
  const TempDir dir;
  write_dataset(dir.file("set"), 20, 30, 4);
  const HemiDataset data = read_hemi_dataset(dir.file("set"));
  const HemiCnn model = train_hemicnn(data, small_config(), short_training(100));
  EXPECT_EQ(model.projection(), HemiProjection::orthographic);  // from the dataset

  const nlohmann::json& info = model.training_info;
  EXPECT_EQ(info["training_sequences"], 16);
  EXPECT_EQ(info["validation_sequences"], 4);
  ASSERT_EQ(info["history"].size(), 10u);
  // Better than always answering the training mean (the net with zero weights), by far.
  HemiCnn mean_only = model;
  for (HemiCnnLayer& layer : mean_only.layers) {
    std::fill(layer.weights.begin(), layer.weights.end(), 0.0f);
    std::fill(layer.bias.begin(), layer.bias.end(), 0.0f);
  }
  double mean_only_loss = 0;
  for (int s = 16; s < 20; ++s)
    mean_only_loss += hemicnn_loss(mean_only.predict(data.sequences[s].values.data(), 25),
                                   data.sequences[s].target, {1.0, 1.0}) /
                      4;
  const double best = info["final"]["validation_loss"];
  EXPECT_LT(best, 0.3 * mean_only_loss) << "mean-only loss " << mean_only_loss;
  EXPECT_LT(best, info["history"][0]["validation_loss"].get<double>());
  double lowest = INFINITY;
  for (const auto& entry : info["history"])
    lowest = std::min(lowest, entry["validation_loss"].get<double>());
  EXPECT_EQ(best, lowest);  // the kept weights are the best ones
  // Each evaluation also logs the mean absolute error of every target. Eq. (5) sums the
  // weighted mean squared errors, so each term bounds its error: w * MAE^2 <= loss (the c term
  // is the mean of three channels, each weighted alike).
  const std::array<double, HemiCnn::kTargets> w = loss_weights(short_training(1).loss);
  for (const auto& entry : info["history"]) {
    const nlohmann::json& mae = entry["validation_mae"];
    const double loss = entry["validation_loss"].get<double>() * (1 + 1e-5);
    const double c = mae["c"].get<double>();
    EXPECT_LE(w[0] * std::pow(mae["L"].get<double>(), 2), loss);
    EXPECT_LE(w[1] * std::pow(mae["a"].get<double>(), 2), loss);
    EXPECT_LE(w[2] * std::pow(mae["b"].get<double>(), 2), loss);
    EXPECT_LE(3 * w[3] * c * c, loss);
    EXPECT_LE(w[6] * std::pow(mae["d"].get<double>(), 2), loss);
    EXPECT_GT(mae["L"].get<double>() + c, 0.0);
  }

  // The standardisations come from the training sequences.
  double mean_l = 0;
  for (int s = 0; s < 16; ++s) mean_l += data.sequences[s].target.lab.x() / 16;
  EXPECT_NEAR(model.target_mean[0], mean_l, 1e-3);

  const HemiSequence& sequence = data.sequences.back();
  const std::vector<float> expected = torch_predict(model, sequence.values.data(), 1, 25);
  const std::vector<float> outputs = raw_outputs(model, sequence.values.data(), 25);
  for (int t = 0; t < HemiCnn::kTargets; ++t)
    EXPECT_NEAR(outputs[t], expected[t], 1e-4f * std::max(1.0f, std::fabs(expected[t])));
}

TEST(HemiCnnTrain, SameSeedGivesIdenticalWeights) {
  const TempDir dir;
  write_dataset(dir.file("set"), 6, 25, 5);
  const HemiDataset data = read_hemi_dataset(dir.file("set"));
  const HemiCnnTrainParams params = short_training(4);
  const HemiCnn a = train_hemicnn(data, small_config(), params);
  const HemiCnn b = train_hemicnn(data, small_config(), params);
  for (std::size_t l = 0; l < a.layers.size(); ++l)
    EXPECT_EQ(a.layers[l].weights, b.layers[l].weights);
  HemiCnnTrainParams other = params;
  other.seed = 2;
  EXPECT_NE(train_hemicnn(data, small_config(), other).layers[0].weights, a.layers[0].weights);
}

TEST(HemiCnnTrain, WeightAveragingKeepsTheRampedMovingAverage) {
  const TempDir dir;
  write_dataset(dir.file("set"), 6, 25, 7);
  const HemiDataset data = read_hemi_dataset(dir.file("set"));
  HemiCnnTrainParams params = short_training(0);
  params.validation_fraction = 0.0;  // keep the last (averaged) weights
  const HemiCnn initial = train_hemicnn(data, small_config(), params);
  params.batches = 1;
  const HemiCnn stepped = train_hemicnn(data, small_config(), params);
  params.weight_averaging = 0.999;
  const HemiCnn averaged = train_hemicnn(data, small_config(), params);
  EXPECT_EQ(averaged.training_info["weight_averaging"], 0.999);
  // One update with the ramped decay min(0.999, (1 + 1) / (10 + 1)) = 2/11.
  int differing = 0;
  for (std::size_t l = 0; l < initial.layers.size(); ++l)
    for (std::size_t k = 0; k < initial.layers[l].weights.size(); ++k) {
      const float w0 = initial.layers[l].weights[k], w1 = stepped.layers[l].weights[k];
      EXPECT_NEAR(averaged.layers[l].weights[k], (2 * w0 + 9 * w1) / 11, 1e-6f);
      differing += w0 != w1;
    }
  EXPECT_GT(differing, 0);  // the step moved the weights, so the average is not trivially equal
}

TEST(HemiCnnTrain, RejectsBadParameters) {
  const TempDir dir;
  write_dataset(dir.file("set"), 2, 25, 6);
  const HemiDataset data = read_hemi_dataset(dir.file("set"));
  auto rejects = [&](auto change) {
    HemiCnnTrainParams params = short_training(1);
    change(params);
    EXPECT_THROW(train_hemicnn(data, small_config(), params), Error);
  };
  rejects([](HemiCnnTrainParams& p) { p.batch_size = 0; });
  rejects([](HemiCnnTrainParams& p) { p.learning_rate = 0; });
  rejects([](HemiCnnTrainParams& p) { p.set_size = 26; });  // sequences hold 25 images
  rejects([](HemiCnnTrainParams& p) { p.validation_fraction = 1.0; });
  rejects([](HemiCnnTrainParams& p) { p.loss.lambda_d = -1; });
  rejects([](HemiCnnTrainParams& p) { p.weight_averaging = 1.0; });
}

}  // namespace
}  // namespace glint::reflectance
